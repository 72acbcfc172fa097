#!/usr/bin/env python3
"""The exactness grid: every method that must be exact, on the three shared scenes'
default views and the Crytek Sponza fly-through keyframes, at four sizes, with the default
point light and a directional light, against the ray-traced reference and its band
(docs/exactness.md). Rewrites the part of docs/exactness.md between
<!-- exactness-grid:begin --> and <!-- exactness-grid:end --> and exits 1 if any exact method
has a sample outside the band.

It takes hours on a 2-core machine: run it niced, after `cargo build --release -p umbra-cli`:

    nice -n 10 python3 scripts/exactness_grid.py [--umbra target/release/umbra] [--scenes DIR]
        [--sizes 640x360,1280x720,1920x1080,2560x1440] [--out target/exactness-grid]
        [--methods hier-triangle,...] [--backend gl|wgpu] [--no-doc]

With `--backend wgpu` each light is verified on its own, and a light the wgpu backend refuses
(its 8-bit stencil cannot hold the scene's winding bound: Conference's directional light) is
listed as refused; the table then goes to stdout only (as with --no-doc).

Each run's JSON is kept in --out (a rerun reuses it: delete the folder to start afresh).
"""
import argparse, datetime, json, os, platform, subprocess, sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ("crytek-sponza", "conference", "sibenik")
SIZES = "640x360,1280x720,1920x1080,2560x1440"
# The directional light of every view: from above, tilted (through Sponza's open roof).
DIRECTIONAL = "0.3,1,0.2,0"
MEASURED_ONLY = lambda m: m == "none" or m.startswith("shadow-map") or m == "all-edges-invert"


def keyframes():
    """The distinct keyframes of bench/sponza.flythrough (the last repeats the first)."""
    keys = []
    for line in open(os.path.join(ROOT, "bench", "sponza.flythrough")):
        line = line.split("#")[0].split()
        if len(line) == 6 and line not in keys:
            keys.append(line)
    return keys


def views(scenes_dir):
    for s in SCENES:
        path = os.path.join(scenes_dir, s + ".obj.gz")
        if not os.path.exists(path):
            print(f"skipping {path}: not found", file=sys.stderr)
            continue
        yield (f"{s} default", path, [])
        if s == "crytek-sponza":
            for i, k in enumerate(keyframes()):
                yield (f"{s} keyframe {i}", path, ["--eye", ",".join(k[:3]), "--target", ",".join(k[3:])])


def exact_methods(umbra):
    out = subprocess.run([umbra, "verify", "--method", "help"], capture_output=True, text=True)
    text = out.stdout + out.stderr
    names = []
    for tok in text.replace(",", " ").split():
        tok = tok.strip("`'\".:;()")
        if tok and tok[0].isalpha() and "-" in tok and tok not in names and not MEASURED_ONLY(tok):
            if tok.endswith(("silhouette", "triangle", "3edge", "1pass", "bvh")):
                names.append(tok)
    if not names:
        sys.exit(f"could not read the method names from `umbra verify --method help`:\n{text}")
    return names


def run(umbra, path, extra, size, methods, out_file, backend="gl"):
    if os.path.exists(out_file):
        return json.load(open(out_file))
    if backend != "gl":
        # One light at a time: a refused light must not take the other with it.
        rows = []
        for k, light in enumerate(["default", DIRECTIONAL]):
            part = run_lights(umbra, path, extra, size, methods, backend, [light])
            if part is None:
                part = [{"method": m, "per_light": [None]} for m in methods]
            for r in part:
                row = next((x for x in rows if x["method"] == r["method"]), None)
                if row is None:
                    rows.append({**r, "per_light": [None, None]})
                    row = rows[-1]
                if "error" in r:
                    row["error"] = r["error"]
                row["per_light"][k] = r["per_light"][0] if r.get("per_light") else None
        json.dump({"rows": rows}, open(out_file, "w"))
        return json.load(open(out_file))
    cmd = [umbra, "verify", "--scene", path, "--size", size, "--method", ",".join(methods), "--json",
           "--light", "default", "--light", DIRECTIONAL, "--explain", "5"] + extra
    r = subprocess.run(cmd, capture_output=True, text=True)
    # 2 with rows on stdout: some methods could not be drawn here (their rows hold "error");
    # the others were verified.
    if r.returncode not in (0, 1, 2) or not r.stdout.strip():
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    rows = json.loads(r.stdout)
    json.dump({"cmd": cmd, "rows": rows, "stderr": r.stderr[-20000:]}, open(out_file, "w"))
    return json.load(open(out_file))


def run_lights(umbra, path, extra, size, methods, backend, lights):
    """`verify --backend BACKEND` with `lights`; None when the backend refuses them."""
    cmd = [umbra, "verify", "--backend", backend, "--scene", path, "--size", size,
           "--method", ",".join(methods), "--json", "--explain", "5"] + extra
    for light in lights:
        cmd += ["--light", light]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode == 2 and not r.stdout.strip() and "8-bit stencil" in r.stderr:
        return None
    if r.returncode not in (0, 1, 2) or not r.stdout.strip():
        sys.exit(f"failed: {' '.join(cmd)}\n{r.stderr}")
    return json.loads(r.stdout)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--umbra", default=os.path.join(ROOT, "target", "release", "umbra"))
    ap.add_argument("--scenes", default=os.environ.get("UMBRA_SCENES", os.path.join(ROOT, "..", "shared", "scenes")))
    ap.add_argument("--sizes", default=SIZES)
    ap.add_argument("--out", default=os.path.join(ROOT, "target", "exactness-grid"))
    ap.add_argument("--no-doc", action="store_true", help="do not rewrite docs/exactness.md")
    ap.add_argument("--methods", help="only these exact methods, comma-separated (default: every exact method)")
    ap.add_argument("--backend", default="gl", choices=["gl", "wgpu"])
    a = ap.parse_args()
    if a.backend != "gl":
        a.no_doc = True
    os.makedirs(a.out, exist_ok=True)
    methods = exact_methods(a.umbra)
    if a.methods:
        unknown = [m for m in a.methods.split(",") if m not in methods]
        if unknown:
            sys.exit(f"--methods: not exact methods of {a.umbra}: {', '.join(unknown)} (exact: {', '.join(methods)})")
        methods = a.methods.split(",")
    print(f"{len(methods)} exact methods: {', '.join(methods)}", file=sys.stderr)
    table = []
    failures = []
    for size in a.sizes.split(","):
        for name, path, extra in views(a.scenes):
            slug = name.replace(" ", "-") + "-" + size
            t0 = datetime.datetime.now()
            res = run(a.umbra, path, extra, size, methods, os.path.join(a.out, slug + ".json"), a.backend)
            rows = [r for r in res["rows"] if "error" not in r]
            failures += [f"{name} {size}: {r['method']} could not be verified: {r['error']}"
                         for r in res["rows"] if "error" in r]
            per_light = [[], []]
            for r in rows:
                for k, l in enumerate(r["per_light"]):
                    if l is not None:
                        per_light[k].append((r["method"], l))
            cells = []
            for k in range(2):
                ls = per_light[k]
                if not ls:
                    cells.append(("refused", "-", "-", "refused", []))
                    continue
                worst = max(l["mismatches_outside_band"] for _, l in ls)
                bad = [f"{m} {l['mismatches_outside_band']}" for m, l in ls if l["mismatches_outside_band"]]
                samples = ls[0][1]["samples"]
                shadowed = ls[0][1]["shadowed_reference"]
                bands = sorted({l["band_samples"] for _, l in ls})
                band = f"{bands[0]}" if len(bands) == 1 else f"{bands[0]}-{bands[-1]}"
                cells.append((samples, shadowed, band, worst, bad))
                failures += [f"{name} {size} light {k}: {b}" for b in bad]
            (s0, sh0, b0, w0, _), (s1, sh1, b1, w1, _) = cells
            table.append(f"| {name} | {size} | {s0} | {sh0} / {sh1} | {b0} | {b1} | **{w0}** | **{w1}** |")
            print(f"{name} {size}: outside band {w0} (point) / {w1} (directional), "
                  f"{(datetime.datetime.now() - t0).total_seconds():.0f} s", file=sys.stderr, flush=True)
    lines = [
        f"Generated by `scripts/exactness_grid.py` on {datetime.date.today()}, {platform.machine()} "
        f"({os.cpu_count()} cores), {'llvmpipe' if a.backend == 'gl' else 'wgpu on lavapipe'}. Every method that must be exact ({len(methods)}: "
        f"{', '.join('`' + m + '`' for m in methods)}); per view and size, two lights: the scene's "
        f"default point light and the directional light `{DIRECTIONAL}`. Band: the samples of the "
        "silhouette methods' band and of the per-triangle methods' (which adds their cancelling "
        "faces), as a range. Outside band: the largest count over the exact methods.",
        "",
        "| view | size | samples | shadowed (point / directional) | band (point) | band (directional) "
        "| outside band (point) | outside band (directional) |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |",
    ] + table
    if failures:
        lines += ["", "Samples outside the band: " + "; ".join(failures) + "."]
    text = "\n".join(lines)
    print(text)
    if not a.no_doc:
        doc = os.path.join(ROOT, "docs", "exactness.md")
        s = open(doc).read()
        begin, end = "<!-- exactness-grid:begin -->", "<!-- exactness-grid:end -->"
        if begin in s and end in s:
            s = s[: s.index(begin) + len(begin)] + "\n" + text + "\n" + s[s.index(end):]
        else:
            s += f"\n{begin}\n{text}\n{end}\n"
        open(doc, "w").write(s)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
