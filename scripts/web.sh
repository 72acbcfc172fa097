#!/usr/bin/env bash
# umbra in the browser (README "In the browser"): builds the umbra binary, umbra-geom's
# WebAssembly module (when absent) and the viewer (a three.js page drawn with web/umbra-three),
# exports SCENE (default: the default scene) with `umbra export` into web/scene/, and serves
# both on http://127.0.0.1:${PORT:-8080}/ (Ctrl-C stops).
#   scripts/web.sh [SCENE] [--ground]
# SCENE is anything `umbra render --scene` takes (default, box, spheres:N, a mesh file).
set -euo pipefail
cd "$(dirname "$0")/.."
scene="${1:-default}"
shift || true
target="${CARGO_TARGET_DIR:-$PWD/target}"
cargo build --release -p umbra-cli
"$target/release/umbra" export "$scene" --out web/scene "$@"
cd web
[ -d node_modules ] || npm ci --no-audit --no-fund
[ -f umbra-geom-wasm/umbra_wasm.wasm ] || node build-wasm.mjs
npm run build --silent
exec node serve.mjs --port "${PORT:-8080}" --root dist --scene scene
