// Needle sides in the browser: Conference's default view at 1280 x 720 on ANGLE on the system's
// EGL (Mesa llvmpipe here), reversed-Z, judged by `umbra verify --external-mask`
// (testlib/exactness.mjs). Along the screen line through the light's projection, hundreds of
// shadow-volume sides are seen nearly edge-on: fan triangles 330 pixels long and 1e-4 pixel
// wide, lying far behind the floor (triangle 59). llvmpipe sets their depth planes up in f32,
// and the interpolated depth of such a needle can come out nearer than the floor; z-fail then
// leaves those fragments uncounted, and 8 lit floor samples on that line read as shadowed.
// The fan pass keeps every fragment's depth within its triangle's corners
// (umbra-three/src/webgl/glsl/fan.frag.glsl): 0 samples outside the band, and the 8 samples
// lit.
//
// Needs what test/browser.test.mjs needs (the umbra binary, the wasm module, /usr/bin/chromium)
// and the shared Conference scene (UMBRA_SCENES, default ../shared/scenes beside the
// repository); skipped with a message when one is absent. About a minute on the 2-core machine.
// Run: cd web && node --test test/needle.test.mjs
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import { mkdtemp, rm } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from '../serve.mjs';
import { build } from '../build.mjs';
import { launch, openViewer, readCanvas, maskAgainstReference } from '../testlib/exactness.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const CHROMIUM = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';
const WASM = path.join(webDir, 'umbra-geom-wasm', 'umbra_wasm.wasm');
const SCENE = path.join(process.env.UMBRA_SCENES || path.join(repo, '..', 'shared', 'scenes'), 'conference.obj.gz');
const UMBRA = [process.env.UMBRA_BIN, process.env.CARGO_TARGET_DIR && path.join(process.env.CARGO_TARGET_DIR, 'release', 'umbra'),
  path.join(repo, 'target', 'release', 'umbra')].find((c) => c && existsSync(c));
const W = 1280;
const H = 720;
// The samples (x right, y down) the needles' depths turned to false shadow: lit in the reference.
const PINNED = [[311, 438], [260, 469], [251, 475], [246, 477], [230, 487], [196, 509], [160, 531], [94, 572]];

const skip = !existsSync(CHROMIUM) ? `${CHROMIUM} is absent (apt-get install chromium)`
  : !existsSync(WASM) ? `${WASM} is absent (node build-wasm.mjs)`
    : !UMBRA ? 'no umbra binary (cargo build --release -p umbra-cli or set UMBRA_BIN)'
      : !existsSync(SCENE) ? `${SCENE} is absent (UMBRA_SCENES)` : false;
if (skip) console.log(`SKIP: ${skip}: needle-side browser test skipped`);

test('Conference 1280x720 on ANGLE/llvmpipe: needle sides behind the floor count, 0 samples outside the band', { skip }, async () => {
  const tmp = await mkdtemp(path.join(tmpdir(), 'umbra-needle-'));
  let server = null;
  let ctx = null;
  try {
    const dist = await build(path.join(tmp, 'dist'));
    execFileSync(UMBRA, ['export', SCENE, '--out', path.join(tmp, 'scene')], { stdio: ['ignore', 'ignore', 'inherit'] });
    server = createServer([['/', dist], ['/scene/', path.join(tmp, 'scene')]]);
    const base = await listen(server, 0);
    ctx = await launch(CHROMIUM, 'egl', tmp);

    // The pinned samples, read from the mask view itself (white = lit).
    const { page, status } = await openViewer(ctx, `${base}?size=${W}x${H}&mask=1&scene=scene/`);
    try {
      assert.equal(status.state, 'ready', `viewer failed: ${status.error}`);
      assert.equal(status.depth, 'reversed-z', 'ANGLE on EGL offers EXT_clip_control: the view is drawn with reversed-Z');
      const { width, rgba } = await readCanvas(page);
      const shadowed = PINNED.filter(([x, y]) => rgba[4 * (y * width + x)] !== 255);
      assert.deepEqual(shadowed, [], `false shadow at ${shadowed.map((p) => `(${p})`).join(' ')} (${status.renderer})`);
    } finally {
      await page.close();
    }

    // The whole view, judged by the oracle.
    const r = await maskAgainstReference(ctx, UMBRA, {
      base, query: 'scene=scene/', scene: SCENE, width: W, height: H, maskPng: path.join(tmp, 'conference.egl.mask.png'),
    });
    assert.equal(r.native.mismatches_outside_band, 0, 'native vs-silhouette');
    assert.equal(r.browser.mismatches_outside_band, 0, `browser mask outside the band (${r.status.renderer}):\n${r.explained.slice(0, 8).join('\n')}`);
  } finally {
    if (ctx) await ctx.close();
    if (server) server.close();
    await rm(tmp, { recursive: true, force: true });
  }
});
