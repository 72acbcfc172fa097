#!/usr/bin/env python3
"""Regenerates the measured table of docs/exactness.md: every method on every scene.

Runs `umbra verify --method all --json` for each scene and pose below and rewrites the part of
docs/exactness.md between the markers <!-- exactness-table:begin --> and
<!-- exactness-table:end -->. Usage (from the repository root, after `cargo build --release`):

    python3 scripts/exactness.py [--umbra target/release/umbra] [--scenes ../shared/scenes]
"""
import argparse, json, os, platform, subprocess, sys, datetime

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

def cases(scenes):
    yield ("default", ["--scene", "default"])
    yield ("default, directional light", ["--scene", "default", "--light", "0.4,1,0.3,0"])
    yield ("spheres:10:100000", ["--scene", "spheres:10:100000"])
    for f in ("crytek-sponza.obj.gz", "conference.obj.gz", "sibenik.obj.gz"):
        p = os.path.join(scenes, f)
        if os.path.exists(p):
            yield (f.replace(".obj.gz", ""), ["--scene", p])
        else:
            print(f"skipping {p}: not found", file=sys.stderr)

def torture_table(results_dir):
    """The torture suite's numbers (written by crates/umbra-verify/tests/torture.rs, one TSV per
    case, at 240x180): per case, the largest outside-band count over the methods that must be
    exact, and the numbers of the methods that are only measured."""
    if not os.path.isdir(results_dir):
        print(f"no torture results in {results_dir}: run `cargo test --release -p umbra-verify --test torture` first",
              file=sys.stderr)
        return []
    measured_only = lambda m: m == "none" or m.startswith("shadow-map") or m == "all-edges-invert"
    rows, methods = [], []
    for f in sorted(os.listdir(results_dir)):
        if not f.endswith(".tsv"):
            continue
        lines = open(os.path.join(results_dir, f)).read().split("\n")
        keys = lines[0].split("\t")
        recs = [dict(zip(keys, l.split("\t"))) for l in lines[1:] if l.strip()]
        exact = [r for r in recs if not measured_only(r["method"])]
        worst = max((int(r["mismatches_outside_band"]) for r in exact), default=0)
        others = {r["method"]: r for r in recs if measured_only(r["method"])}
        for m in others:
            if m not in methods:
                methods.append(m)
        rows.append((f[:-4], len(exact), worst, others))
    out = ["", f"Torture suite (`cargo test --release -p umbra-verify --test torture`, 240x180, results of "
           f"{datetime.date.fromtimestamp(max(os.path.getmtime(os.path.join(results_dir, f)) for f in os.listdir(results_dir)))}): "
           "for each case, the largest `mismatches_outside_band` over every method that must be exact, "
           "and `mismatches_outside_band` / `band_mismatches` of the methods that are only measured.", "",
           "| case | exact methods | worst outside band | " + " | ".join(f"`{m}`" for m in methods) + " |",
           "| --- | ---: | ---: | " + " | ".join("---:" for _ in methods) + " |"]
    for name, n, worst, others in rows:
        cells = [f"{others[m]['mismatches_outside_band']} / {others[m]['band_mismatches']}" if m in others else "" for m in methods]
        out.append(f"| {name} | {n} | **{worst}** | " + " | ".join(cells) + " |")
    return out

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--umbra", default=os.path.join(ROOT, "target", "release", "umbra"))
    ap.add_argument("--scenes", default=os.environ.get("UMBRA_SCENES", os.path.join(ROOT, "..", "shared", "scenes")))
    ap.add_argument("--size", default="1280x720")
    ap.add_argument("--torture", default=os.path.join(ROOT, "target", "test-output", "torture", "results"),
                    help="the torture suite's per-case TSVs (crates/umbra-verify/tests/torture.rs writes them)")
    a = ap.parse_args()
    rows = []
    renderer = ""
    for name, args in cases(a.scenes):
        cmd = [a.umbra, "verify", "--method", "all", "--json", "--size", a.size] + args
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode not in (0, 1):
            print(r.stderr, file=sys.stderr)
            sys.exit(f"failed: {' '.join(cmd)}")
        for m in json.loads(r.stdout):
            rows.append((name, m))
        for line in r.stderr.splitlines():
            if "llvmpipe" in line or "renderer" in line:
                renderer = line
    out = ["| scene | method | samples | shadowed (ref) | mismatches | band | band mismatches | outside band | band mismatch % |",
           "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for name, m in rows:
        pct = 100.0 * m["band_mismatches"] / m["band_samples"] if m["band_samples"] else 0.0
        out.append(f"| {name} | `{m['method']}` | {m['samples']} | {m['shadowed_reference']} | {m['mismatches']} | "
                   f"{m['band_samples']} | {m['band_mismatches']} | **{m['mismatches_outside_band']}** | {pct:.2f} |")
    stamp = (f"Generated by `scripts/exactness.py` on {datetime.date.today()} at {a.size}, "
             f"{platform.machine()} ({os.cpu_count()} cores). Default camera and light of each scene.")
    out += torture_table(a.torture)
    table = "\n".join([stamp, ""] + out)
    path = os.path.join(ROOT, "docs", "exactness.md")
    text = open(path).read()
    begin, end = "<!-- exactness-table:begin -->", "<!-- exactness-table:end -->"
    i, j = text.index(begin) + len(begin), text.index(end)
    open(path, "w").write(text[:i] + "\n" + table + "\n" + text[j:])
    print(table)

if __name__ == "__main__":
    main()
