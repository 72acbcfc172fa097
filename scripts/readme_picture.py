#!/usr/bin/env python3
"""Makes docs/umbra-vs-shadow-map.png, the README's picture: one view rendered by umbra
(`cpu-silhouette`) and by the 2K cube shadow map (`shadow-map-cube:2048`), side by side, with an
enlarged crop, and the number of samples each gets wrong outside the band (`umbra verify`'s
`mismatches_outside_band`); and docs/verify-diff.png, both methods' `umbra verify --diff` images
side by side (docs/guide.md). Needs only the umbra binary and Pillow (`pip install pillow`).
The defaults are the pictures in the repository; regenerate them with:

    cargo build --release -p umbra-cli
    python3 scripts/readme_picture.py

Options: --umbra BIN (default target/release/umbra), --scene FILE (default
$UMBRA_SCENES/crytek-sponza.obj.gz, UMBRA_SCENES defaulting to ../shared/scenes), --size WxH
(1280x720), --eye X,Y,Z --target X,Y,Z (-5,2.5,0 and -10,0.5,-1: under Sponza's west gallery,
looking at the lion relief), --light X,Y,Z[,W] (default: the scene's own point light), --crop
WxH (160x90 image pixels), --at X,Y (the crop's corner, 880,150; `auto`: the window where the
map has the most samples wrong), --out FILE, --diff-out FILE (`none`: not written), --keep DIR
(keep the renders and diffs there).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

from PIL import Image, ImageDraw, ImageFont

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXACT = "cpu-silhouette"
MAP = "shadow-map-cube:2048"
FALSE_SHADOW = (255, 0, 0)
FALSE_LIGHT = (0, 0, 255)
YELLOW = (255, 220, 0)


def view_flags(a):
    flags = ["--scene", a.scene, "--size", a.size]
    for name in ("eye", "target", "light"):
        value = getattr(a, name)
        if value:
            flags += [f"--{name}", value]
    return flags


def run(cmd, ok=(0,)):
    print("+", " ".join(cmd), file=sys.stderr, flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode not in ok:
        sys.exit(f"failed ({r.returncode}): {' '.join(cmd)}\n{r.stderr}")
    return r.stdout


def worst_window(diff, cw, ch):
    """Top-left corner of the cw x ch window of `diff` with the most red or blue pixels."""
    w, h = diff.size
    step = 8
    mask = Image.new("L", diff.size, 0)
    px, mp = diff.load(), mask.load()
    for y in range(h):
        for x in range(w):
            if px[x, y][:3] in (FALSE_SHADOW, FALSE_LIGHT):
                mp[x, y] = 255
    gw, gh = w // step, h // step
    cells = mask.resize((gw, gh), Image.BOX).load()
    kw, kh = cw // step, ch // step
    best, corner = -1, (0, 0)
    for gy in range(gh - kh + 1):
        for gx in range(gw - kw + 1):
            s = sum(cells[gx + i, gy + j] for j in range(kh) for i in range(kw))
            if s > best:
                best, corner = s, (gx * step, gy * step)
    return corner, best


def main():
    scenes = os.environ.get("UMBRA_SCENES", os.path.join(ROOT, "..", "shared", "scenes"))
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--umbra", default=os.path.join(ROOT, "target", "release", "umbra"))
    p.add_argument("--scene", default=os.path.normpath(os.path.join(scenes, "crytek-sponza.obj.gz")))
    p.add_argument("--size", default="1280x720")
    p.add_argument("--eye", default="-5,2.5,0")
    p.add_argument("--target", default="-10,0.5,-1")
    p.add_argument("--light")
    p.add_argument("--crop", default="160x90")
    p.add_argument("--at", default="880,150")
    p.add_argument("--out", default=os.path.join(ROOT, "docs", "umbra-vs-shadow-map.png"))
    p.add_argument("--diff-out", default=os.path.join(ROOT, "docs", "verify-diff.png"))
    p.add_argument("--keep")
    a = p.parse_args()
    cw, ch = (int(v) for v in a.crop.split("x"))

    tmp = a.keep or tempfile.mkdtemp(prefix="umbra-picture-")
    os.makedirs(tmp, exist_ok=True)
    flags = view_flags(a)
    renders = {}
    for m in (EXACT, MAP):
        out = os.path.join(tmp, m.replace(":", "-") + ".png")
        run([a.umbra, "render", *flags, "--method", m, "--out", out])
        renders[m] = Image.open(out).convert("RGB")
    diff_base = os.path.join(tmp, "diff.png")
    rows = json.loads(run([a.umbra, "verify", *flags, "--method", f"{EXACT},{MAP}", "--json",
                           "--diff", diff_base], ok=(0, 1)))
    wrong = {r["method"]: r["mismatches_outside_band"] for r in rows}
    diff_files = [f for f in os.listdir(tmp) if f.startswith("diff") and "shadow-map" in f]
    if len(diff_files) != 1:
        sys.exit(f"expected one diff image of {MAP} in {tmp}, found {diff_files}")
    diff = Image.open(os.path.join(tmp, diff_files[0])).convert("RGB")
    if a.at != "auto":
        cx, cy = (int(v) for v in a.at.split(","))
    else:
        (cx, cy), _ = worst_window(diff, cw, ch)
    print(f"crop {cw}x{ch} at ({cx}, {cy}); outside the band: {wrong}", file=sys.stderr)

    w, h = renders[EXACT].size
    half = (w // 2, h // 2)
    zoom = half[0] / cw
    crop_size = (half[0], round(ch * zoom))
    font = ImageFont.load_default(size=max(14, w // 64))
    strip = font.size + 14
    gap = 4
    titles = {
        EXACT: f"umbra, {EXACT}: {wrong[EXACT]:,} samples wrong",
        MAP: f"2K cube shadow map: {wrong[MAP]:,} samples wrong",
    }
    sheet = Image.new("RGB", (2 * half[0] + gap, 2 * strip + half[1] + crop_size[1]), (0, 0, 0))
    draw = ImageDraw.Draw(sheet)
    s = half[0] / w
    for col, m in enumerate((EXACT, MAP)):
        x0 = col * (half[0] + gap)
        draw.text((x0 + 8, 7), titles[m], font=font, fill=(255, 255, 255))
        sheet.paste(renders[m].resize(half, Image.LANCZOS), (x0, strip))
        draw.rectangle((x0 + cx * s, strip + cy * s, x0 + (cx + cw) * s, strip + (cy + ch) * s),
                       outline=YELLOW, width=2)
        y1 = strip + half[1]
        draw.text((x0 + 8, y1 + 7), f"the yellow frame, {zoom:g}x", font=font, fill=YELLOW)
        crop = renders[m].crop((cx, cy, cx + cw, cy + ch)).resize(crop_size, Image.NEAREST)
        sheet.paste(crop, (x0, y1 + strip))
    save(sheet, a.out)

    if a.diff_out != "none":
        # The verdicts themselves: both methods' `umbra verify --diff` images, side by side.
        legend = "red: false shadow   blue: false light   grey: the band (within the machinery's precision)"
        sheet = Image.new("RGB", (2 * half[0] + gap, 2 * strip + half[1]), (0, 0, 0))
        draw = ImageDraw.Draw(sheet)
        for col, m in enumerate((EXACT, MAP)):
            x0 = col * (half[0] + gap)
            name = [f for f in os.listdir(tmp) if f.startswith("diff.") and m.replace(":", "_") in f][0]
            image = Image.open(os.path.join(tmp, name)).convert("RGB")
            draw.text((x0 + 8, 7), f"{m}: {wrong[m]:,} wrong outside the band", font=font, fill=(255, 255, 255))
            sheet.paste(image.resize(half, Image.BOX), (x0, strip))
        draw.text((8, strip + half[1] + 7), legend, font=font, fill=(255, 255, 255))
        save(sheet, a.diff_out)


def save(sheet, path):
    sheet = sheet.quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    sheet.save(path, optimize=True)
    print(f"wrote {path} ({os.path.getsize(path)} bytes)", file=sys.stderr)


if __name__ == "__main__":
    main()
