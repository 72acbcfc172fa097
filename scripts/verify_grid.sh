#!/usr/bin/env bash
# An exactness grid of chosen methods: `umbra verify` of one or more methods (default hier-triangle)
# on the three shared scenes' default views and on the Crytek Sponza fly-through keyframes
# (bench/sponza.flythrough), at 640x360, 1920x1080 and 3840x2160. One TSV line per view, size
# and method: samples, shadowed (reference), band, band mismatches, mismatches outside the band
# (must be 0 for an exact method), reference and render milliseconds.
#
#   scripts/verify_grid.sh [METHODS] [SIZES]      e.g. scripts/verify_grid.sh hier-triangle 640x360
#
# UMBRA_SCENES (default ../shared/scenes) locates the scenes; a missing scene is skipped with a
# message. UMBRA (default target/release/umbra) is the binary. Slow: the 3840x2160 reference
# alone takes minutes per view on 2 cores; run it on an idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
methods="${1:-hier-triangle}"
sizes="${2:-640x360 1920x1080 3840x2160}"
umbra="${UMBRA:-target/release/umbra}"
scenes="${UMBRA_SCENES:-$PWD/../shared/scenes}"
[ -x "$umbra" ] || { echo "build it first: cargo build --release -p umbra-cli" >&2; exit 2; }

views=()
for s in crytek-sponza conference sibenik; do
  views+=("$s|default||")
done
k=0
while read -r ex ey ez tx ty tz; do
  views+=("crytek-sponza|keyframe$k|$ex,$ey,$ez|$tx,$ty,$tz")
  k=$((k + 1))
done < <(grep -v '^#' bench/sponza.flythrough | grep -v '^[[:space:]]*$')

printf 'scene\tview\tsize\tmethod\tsamples\tshadowed\tband\tband_mismatches\toutside_band\treference_ms\trender_ms\n'
for size in $sizes; do
  for v in "${views[@]}"; do
    IFS='|' read -r scene view eye target <<< "$v"
    file="$scenes/$scene.obj.gz"
    if [ ! -f "$file" ]; then
      echo "SKIPPED: $file not found (set UMBRA_SCENES)" >&2
      continue
    fi
    args=(verify --scene "$file" --method "$methods" --size "$size" --json)
    [ -n "$eye" ] && args+=(--eye "$eye" --target "$target")
    "$umbra" "${args[@]}" 2>/dev/null | python3 -c '
import json, sys
scene, view, size = sys.argv[1:4]
for m in json.load(sys.stdin):
    print("\t".join(str(x) for x in [scene, view, size, m["method"], m["samples"], m["shadowed_reference"],
        m["band_samples"], m["band_mismatches"], m["mismatches_outside_band"],
        round(m["reference_ms"]), round(m["render_ms"])]), flush=True)
' "$scene" "$view" "$size"
  done
done
