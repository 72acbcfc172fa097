#!/usr/bin/env bash
# ray-bvh against its peers on a GPU machine: the three fly-throughs at 1920x1080 with none,
# cpu-silhouette (with and without the receiver cull, --volume-cull both), vs-silhouette,
# hier-triangle, shadow-map-cube:2048, shadow-map-cube:8192 and ray-bvh in one
# interleaved `umbra bench` run per scene (GL through EGL), the Sponza fly-through on wgpu
# (Vulkan) too, and `umbra verify` of ray-bvh on Sponza at 1920x1080, point and directional
# light. JSON and logs go to $OUT (default target/gpu-bench).
#
# Two steps, because a lent GPU machine has no Rust toolchain and no network:
#
#   scripts/gpu_bench.sh prepare     # here: release build, stripped into .gpu/umbra, the scenes
#                                    # copied to .gpu/scenes, the GL/Vulkan loader packages to
#                                    # .gl/ (apt-get download; .gpu/ and .gl/ are git-ignored
#                                    # through .git/info/exclude)
#   scripts/gpu_bench.sh run         # there, from the repository root, carrying .gpu and .gl
#
# `run` unpacks the loaders when .gl/ holds them, points Vulkan and EGL at NVIDIA's driver
# files when they exist, prints the devices, and runs the benches (about 5 minutes on an H100).
# Rays per second in docs/benchmarks.md: 1920 x 1080 pixels per light over the mean of the
# "rays" + "resume" stages (background pixels included: they cost a read each).
set -euo pipefail
cd "$(dirname "$0")/.."
mode="${1:-run}"
out="${OUT:-target/gpu-bench}"
scenes_src="${UMBRA_SCENES:-$PWD/../shared/scenes}"

if [ "$mode" = prepare ]; then
  cargo build --release -p umbra-cli
  mkdir -p .gpu/scenes .gl
  grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || echo /.gpu/ >> "$(git rev-parse --git-path info/exclude)"
  grep -qx '/.gl/' .git/info/exclude 2>/dev/null || echo /.gl/ >> "$(git rev-parse --git-path info/exclude)"
  strip -o .gpu/umbra target/release/umbra
  cp "$scenes_src"/crytek-sponza.obj.gz "$scenes_src"/conference.obj.gz "$scenes_src"/sibenik.obj.gz .gpu/scenes/
  cp bench/*.flythrough .gpu/
  o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
  mkdir -p /tmp/amd64/partial
  # shellcheck disable=SC2086
  apt-get $o update >/dev/null
  # shellcheck disable=SC2086
  (cd .gl && apt-get $o download libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
  du -sh .gpu .gl
  exit 0
fi

[ "$mode" = run ] || { echo "usage: scripts/gpu_bench.sh prepare|run" >&2; exit 2; }
[ -x .gpu/umbra ] || { echo "no .gpu/umbra: run 'scripts/gpu_bench.sh prepare' first and carry .gpu" >&2; exit 2; }
if compgen -G ".gl/*.deb" >/dev/null; then
  for f in .gl/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
[ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ] &&
  export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -f /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json ] &&
  export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
mkdir -p "$out"
umbra=.gpu/umbra
export UMBRA_SCENES=$PWD/.gpu/scenes
{ nvidia-smi -L || true; "$umbra" info --backend gl || true; "$umbra" info --backend wgpu || true; } > "$out/devices.log" 2>&1
methods=none,cpu-silhouette,vs-silhouette,hier-triangle,shadow-map-cube:2048,shadow-map-cube:8192,ray-bvh
for s in crytek-sponza:sponza conference:conference sibenik:sibenik; do
  scene=${s%%:*}; fly=${s##*:}
  # --volume-cull both: cpu-silhouette culled against the receivers and, as
  # cpu-silhouette@cull-off, unculled, in the same interleaved run (volume_fragments per row).
  "$umbra" bench --scene ".gpu/scenes/$scene.obj.gz" --flythrough ".gpu/$fly.flythrough" --methods "$methods" \
    --volume-cull both --size 1920x1080 --frames 16 --warmup 2 --json > "$out/bench_$fly.json" 2> "$out/bench_$fly.log" ||
    echo "bench $fly failed (see bench_$fly.log)" >&2
done
"$umbra" bench --scene .gpu/scenes/crytek-sponza.obj.gz --flythrough .gpu/sponza.flythrough \
  --methods none,cpu-silhouette,shadow-map-cube:2048,ray-bvh --backend gl,wgpu \
  --size 1920x1080 --frames 16 --warmup 2 --json > "$out/bench_sponza_wgpu.json" 2> "$out/bench_sponza_wgpu.log" ||
  echo "bench gl,wgpu failed (see bench_sponza_wgpu.log)" >&2
"$umbra" verify --scene .gpu/scenes/crytek-sponza.obj.gz --method ray-bvh,cpu-silhouette --size 1920x1080 \
  --light default --light 0.3,1,0.2,0 --json > "$out/verify_sponza.json" 2> "$out/verify_sponza.log" ||
  echo "verify: exit $? (1 = a sample outside the band)" >&2
python3 - "$out" <<'PY' || true
import json, sys, os
out = sys.argv[1]
for f in sorted(os.listdir(out)):
    if not (f.startswith("bench_") and f.endswith(".json")):
        continue
    rows = json.load(open(os.path.join(out, f)))
    print(f)
    for r in rows:
        st = r.get("stages", {})
        rays = st.get("rays", 0) + st.get("resume", 0)
        extra = f"  {r['width'] * r['height'] / rays / 1e6:.2f} G pixel-rays/s" if rays else ""
        if r.get("volume_fragments") is not None:
            extra += f"  {r['volume_fragments'] / 1e6:.1f} M volume fragments" + ("" if r.get("volume_cull") else " (unculled)")
        print(f"  {r['method']:<22} {r.get('backend', 'gl'):<5} mean {r['mean_ms'] or 0:9.2f} ms{extra}")
PY
