// Builds umbra-geom's WebAssembly module (crates/umbra-wasm) and copies it next to its
// JavaScript: web/umbra-geom-wasm/umbra_wasm.wasm.
//
//   cargo build --release --target wasm32-unknown-unknown -p umbra-wasm
//
// with the release profile's debug info off and the symbols stripped (the workspace keeps
// debug info for profiling native builds; a browser module has no use for it), and with
// link-time optimisation in one codegen unit (a module about 9 % smaller, as fast). Needs the
// target: rustup target add wasm32-unknown-unknown. CARGO_TARGET_DIR is honoured.
//
// Usage: node build-wasm.mjs   (or npm run build:wasm)
import { execFileSync } from 'node:child_process';
import { copyFileSync, statSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const webDir = path.dirname(fileURLToPath(import.meta.url));
const repo = path.join(webDir, '..');
const TARGET = 'wasm32-unknown-unknown';

export function buildWasm() {
  execFileSync('cargo', ['build', '--release', '--target', TARGET, '-p', 'umbra-wasm'], {
    cwd: repo,
    stdio: 'inherit',
    env: {
      ...process.env,
      CARGO_PROFILE_RELEASE_DEBUG: '0',
      CARGO_PROFILE_RELEASE_STRIP: 'symbols',
      CARGO_PROFILE_RELEASE_LTO: 'true',
      CARGO_PROFILE_RELEASE_CODEGEN_UNITS: '1',
    },
  });
  const targetDir = process.env.CARGO_TARGET_DIR ? path.resolve(repo, process.env.CARGO_TARGET_DIR) : path.join(repo, 'target');
  const built = path.join(targetDir, TARGET, 'release', 'umbra_wasm.wasm');
  const out = path.join(webDir, 'umbra-geom-wasm', 'umbra_wasm.wasm');
  copyFileSync(built, out);
  return { out, bytes: statSync(out).size };
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const { out, bytes } = buildWasm();
  console.log(`${path.relative(process.cwd(), out)}: ${bytes} bytes`);
}
