// Preprocessing time of umbra-geom's WebAssembly module (web/umbra-geom-wasm/) against native
// `umbra export`, for one scene: a measurement, never a test.
//
//   node bench-wasm.mjs SCENE [--runs N] [--chromium]
//
// 1. `umbra export SCENE` (wall clock: loading the file, preprocessing, writing the buffers).
// 2. Its positions.bin and indices.bin fed back as an indexed geometry: the module's prepare()
//    (copy in, check, weld, adjacency, sides-data, caps-data, edge triangles, normals, copy
//    out) timed over N runs in Node, and, with --chromium, in headless Chromium on a page
//    served from 127.0.0.1 (UMBRA_CHROMIUM, default /usr/bin/chromium).
// Also prints the .wasm's size, raw and gzip -9. Native preprocessing without the loading:
// cargo run --release -p umbra-wasm --example prepare_time -- SCENE.
// Needs target/release/umbra (or UMBRA_BIN) and node build-wasm.mjs.
import { execFileSync } from 'node:child_process';
import { existsSync, readFileSync } from 'node:fs';
import { mkdtemp, readFile, rm, writeFile } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { gzipSync } from 'node:zlib';
import { createServer, listen } from './serve.mjs';
import { launch } from './testlib/exactness.mjs';
import { loadUmbraGeom } from './umbra-geom-wasm/index.js';

const webDir = path.dirname(fileURLToPath(import.meta.url));
const repo = path.join(webDir, '..');
const moduleDir = path.join(webDir, 'umbra-geom-wasm');
const WASM = path.join(moduleDir, 'umbra_wasm.wasm');

const argv = process.argv.slice(2);
const scene = argv.find((a, i) => !a.startsWith('--') && argv[i - 1] !== '--runs');
const runs = Number(argv[argv.indexOf('--runs') + 1] || 5) || 5;
if (!scene) {
  console.error('usage: node bench-wasm.mjs SCENE [--runs N] [--chromium]');
  process.exit(2);
}
const umbra = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'), path.join(repo, 'target', 'release', 'umbra')].find((c) => c && existsSync(c));
if (!umbra) throw new Error('no umbra binary: cargo build --release -p umbra-cli, or set UMBRA_BIN');

const stats = (ms) => {
  const s = [...ms].sort((a, b) => a - b);
  return `median ${s[s.length >> 1].toFixed(0)} ms, min ${s[0].toFixed(0)} ms over ${s.length} runs`;
};

const wasm = readFileSync(WASM);
console.log(`${path.relative(process.cwd(), WASM)}: ${wasm.length} bytes, gzip -9 ${gzipSync(wasm, { level: 9 }).length} bytes`);

const tmp = await mkdtemp(path.join(tmpdir(), 'umbra-bench-wasm-'));
try {
  const out = path.join(tmp, 'export');
  const native = [];
  for (let i = 0; i < runs; i++) {
    const start = performance.now();
    execFileSync(umbra, ['export', scene, '--out', out], { stdio: ['ignore', 'ignore', i === 0 ? 'inherit' : 'ignore'] });
    native.push(performance.now() - start);
  }
  console.log(`native umbra export (load + preprocess + write): ${stats(native)}`);
  const positions = new Float32Array((await readFile(path.join(out, 'positions.bin'))).buffer.slice(0));
  const index = new Uint32Array((await readFile(path.join(out, 'indices.bin'))).buffer.slice(0));

  let start = performance.now();
  const geom = await loadUmbraGeom(wasm);
  console.log(`node: instantiate ${(performance.now() - start).toFixed(0)} ms`);
  const node = [];
  let p;
  for (let i = 0; i < runs; i++) {
    start = performance.now();
    p = geom.prepare({ name: scene, positions, index });
    node.push(performance.now() - start);
  }
  console.log(`node ${process.version}: prepare ${p.counts.triangles} triangles, ${p.counts.sidesDataRecords} edge records, maxMult ${p.maxMult}: ${stats(node)}; wasm memory ${(geom.memoryBytes() / 2 ** 20).toFixed(0)} MiB`);

  if (argv.includes('--chromium')) {
    const page = `<!doctype html><meta charset="utf-8"><script type="module">
import { loadUmbraGeom } from './umbra-geom-wasm/index.js';
window.bench = async (runs) => {
  const [positions, index] = await Promise.all(['positions.bin', 'indices.bin'].map(async (f) => (await fetch('export/' + f)).arrayBuffer()));
  let start = performance.now();
  const geom = await loadUmbraGeom();
  const instantiate = performance.now() - start;
  const times = [];
  let p;
  for (let i = 0; i < runs; i++) {
    start = performance.now();
    p = geom.prepare({ name: 'scene', positions: new Float32Array(positions), index: new Uint32Array(index) });
    times.push(performance.now() - start);
  }
  return { instantiate, times, triangles: p.counts.triangles, userAgent: navigator.userAgent };
};
window.ready = true;
</script>`;
    await writeFile(path.join(tmp, 'index.html'), page);
    // The viewer's own server (serve.mjs, which serves .wasm as application/wasm) and browser
    // launch (testlib); WebGL is not used, so the implementation does not matter.
    const server = createServer([['/', tmp], ['/umbra-geom-wasm/', moduleDir]]);
    const base = await listen(server);
    const browser = await launch(process.env.UMBRA_CHROMIUM || '/usr/bin/chromium', 'swiftshader', tmp);
    try {
      const tab = await browser.newPage();
      await tab.goto(base);
      await tab.waitForFunction(() => window.ready === true);
      const r = await tab.evaluate((n) => window.bench(n), runs);
      console.log(`chromium (${r.userAgent.match(/Chrome\/[\d.]+/)?.[0]}): instantiate ${r.instantiate.toFixed(0)} ms; prepare ${r.triangles} triangles: ${stats(r.times)}`);
    } finally {
      await browser.close();
      server.close();
    }
  }
} finally {
  await rm(tmp, { recursive: true, force: true });
}
