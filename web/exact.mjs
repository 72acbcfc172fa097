// The browser's exactness grid (docs/web.md): every scene x size x WebGL 2
// implementation x viewer query, the viewer's shadow mask judged by `umbra verify
// --external-mask` (testlib/exactness.mjs) against the ray-traced reference with the oracle's
// band, next to native vs-silhouette. Too slow for CI on big scenes at big sizes (software
// rasterisers): test/browser.test.mjs runs the CI subset.
//
// Usage: node exact.mjs [--scenes A,B,..] [--sizes 640x360,..] [--impl swiftshader,egl]
//                       [--query 'depth=standard'] [--keep DIR] [--explain N]
//   --scenes  scene specs or mesh files (default: the three shared scenes under UMBRA_SCENES,
//             default ../shared/scenes beside the repository)
//   --keep    write every mask and diff image into DIR
//   --explain print the first N wrong samples of each row (umbra verify --explain)
// The frame time column is the first frame's (shader compilation included).
// Needs the umbra binary (UMBRA_BIN, else target/release/umbra) and /usr/bin/chromium.
import { execFileSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { mkdtemp, mkdir, rm } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from './serve.mjs';
import { build } from './build.mjs';
import { launch, maskAgainstReference } from './testlib/exactness.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const repo = path.join(here, '..');
const arg = (name, dflt) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? process.argv[i + 1] : dflt;
};
const scenesDir = process.env.UMBRA_SCENES || path.join(repo, '..', 'shared', 'scenes');
const scenes = (arg('--scenes', ['crytek-sponza', 'conference', 'sibenik'].map((s) => path.join(scenesDir, `${s}.obj.gz`)).join(','))).split(',');
const sizes = arg('--sizes', '640x360').split(',');
const impls = arg('--impl', 'swiftshader,egl').split(',');
const query = arg('--query', '');
const keep = arg('--keep', null);
const explain = Number(arg('--explain', '0'));
const umbra = [process.env.UMBRA_BIN, path.join(repo, 'target', 'release', 'umbra')].find((c) => c && existsSync(c));
if (!umbra) throw new Error('no umbra binary: cargo build --release -p umbra-cli or set UMBRA_BIN');

const tmp = await mkdtemp(path.join(tmpdir(), 'umbra-exact-'));
const out = keep ? path.resolve(keep) : path.join(tmp, 'out');
await mkdir(out, { recursive: true });
const dist = await build(path.join(tmp, 'dist'));
const mounts = [['/', dist]];
scenes.forEach((s, i) => {
  const dir = path.join(tmp, `scene${i}`);
  execFileSync(umbra, ['export', s, '--out', dir], { stdio: ['ignore', 'ignore', 'inherit'] });
  mounts.push([`/scene${i}/`, dir]);
});
const server = createServer(mounts);
const base = await listen(server, 0);
console.log('| scene | implementation | size | query | native outside band | browser outside band | false shadow | false light | band samples | frame ms |');
console.log('| --- | --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |');
try {
  for (const impl of impls) {
    const ctx = await launch(process.env.UMBRA_CHROMIUM || '/usr/bin/chromium', impl, tmp);
    try {
      for (const [i, scene] of scenes.entries()) {
        for (const size of sizes) {
          const [width, height] = size.split('x').map(Number);
          const name = `${path.basename(scene).replace(/\..*$/, '')}.${impl}.${size}${query ? '.' + query.replace(/[^A-Za-z0-9]+/g, '_') : ''}`;
          const r = await maskAgainstReference(ctx, umbra, {
            base, query: `scene=scene${i}/&${query}`, scene, width, height,
            maskPng: path.join(out, `${name}.mask.png`), explain: 1_000_000, diff: keep ? path.join(out, `${name}.diff.png`) : null,
          });
          console.log(`| ${path.basename(scene)} | ${impl} | ${size} | ${query || '-'} | ${r.native.mismatches_outside_band} | ${r.browser.mismatches_outside_band} | ${r.falseShadow} | ${r.falseLight} | ${r.browser.band_samples} | ${r.status.frameMs.toFixed(0)} |`);
          for (const l of r.explained.slice(0, explain)) console.log(`    ${l}`);
        }
      }
    } finally {
      await ctx.close();
    }
  }
} finally {
  server.close();
  await rm(tmp, { recursive: true, force: true });
}
