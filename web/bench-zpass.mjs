// umbra-three's frame with and without z-pass, A/B in one browser: a measurement, never a
// test. Each scene is opened twice in the viewer (model=..., its default view and light,
// timing=1): as the package draws it (z-pass where umbra_geom::clearance proves it exact,
// z-fail elsewhere) and with zpass=0 (every light z-fail); the two pages' frames are drawn
// interleaved, so that the load of a shared machine falls on both alike.
//
//   node bench-zpass.mjs [--size WxH] [--frames N] [--impl swiftshader|egl] [--orbit K] [--timing 0]
//                        [--baseline DIST] [SCENE.obj.gz ...]
//
// Prints, per scene and page, the mean and min frame (ms, performance.now() around a frame made
// synchronous by a readPixels, with every pass waited for), the mean time per pass
// (umbra.info.passes) and how many of the frames' lights were counted z-pass. --timing 0: the
// frames without the per-pass waits (no passes). --baseline DIST: a third page, another build
// of the viewer (node build.mjs --outdir DIST in another checkout), drawn in the same rounds. --orbit K adds K
// views turned about the default target (yaw steps of 360/K degrees), as a user orbiting would.
// Scenes: file names in UMBRA_SCENES (default ../shared/scenes beside the repository);
// default the three shared scenes. Needs /usr/bin/chromium (UMBRA_CHROMIUM), node
// build-wasm.mjs, npm ci.
import { mkdtemp, rm } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from './serve.mjs';
import { build } from './build.mjs';
import { launch, openViewer } from './testlib/exactness.mjs';

const webDir = path.dirname(fileURLToPath(import.meta.url));
const argv = process.argv.slice(2);
const opt = (name, dflt) => (argv.includes(name) ? argv[argv.indexOf(name) + 1] : dflt);
const size = opt('--size', '640x360');
const frames = Number(opt('--frames', '5'));
const impl = opt('--impl', 'swiftshader');
const orbit = Number(opt('--orbit', '0'));
const timing = opt('--timing', '1');
const baseline = opt('--baseline', null);
const valued = new Set(['--size', '--frames', '--impl', '--orbit', '--timing', '--baseline']);
const named = argv.filter((a, i) => !a.startsWith('--') && !valued.has(argv[i - 1]));
const scenes = named.length ? named : ['crytek-sponza.obj.gz', 'conference.obj.gz', 'sibenik.obj.gz'];
const SCENES_DIR = process.env.UMBRA_SCENES || path.join(webDir, '..', '..', 'shared', 'scenes');
const CHROMIUM = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';

const tmp = await mkdtemp(path.join(tmpdir(), 'umbra-bench-zpass-'));
const mounts = [['/', await build(path.join(tmp, 'dist'))], ['/scenes/', SCENES_DIR]];
if (baseline) mounts.push(['/baseline/', path.resolve(baseline)], ['/baseline/scenes/', SCENES_DIR]);
const server = createServer(mounts);
const base = await listen(server, 0);
const ctx = await launch(CHROMIUM, impl, tmp);

// One frame of a ready page: its time, passes and counts.
const draw = (page) => page.evaluate(async () => {
  const u = window.umbra;
  const n = u.frames;
  u.redraw();
  await new Promise((resolve) => {
    const check = () => (u.frames > n ? resolve() : setTimeout(check, 2));
    check();
  });
  const info = u.info();
  return { ms: u.frameMs, passes: info.passes, zpass: info.zpass, casters: info.casters };
});

// The view turned about its target by `yaw` radians (the viewer's orbit).
const turned = (view, yaw) => {
  const off = [0, 1, 2].map((k) => view.eye[k] - view.target[k]);
  const [c, s] = [Math.cos(yaw), Math.sin(yaw)];
  return [view.target[0] + c * off[0] + s * off[2], view.eye[1], view.target[2] - s * off[0] + c * off[2]];
};

const mean = (a) => a.reduce((s, v) => s + v, 0) / a.length;
console.log(`${new Date().toISOString()} ${impl} ${size}, ${frames} frames per page and view, interleaved`);
try {
  for (const scene of scenes) {
    const url = `${base}?size=${size}&timing=${timing}&model=scenes/${scene}`;
    const pages = {};
    const variants = [['package', url], ['zpass=0', `${url}&zpass=0`]];
    if (baseline) variants.push(['baseline', url.replace(base, `${base}baseline/`)]);
    for (const [name, u] of variants) {
      const v = await openViewer(ctx, u);
      if (v.status.state !== 'ready') throw new Error(`${scene}: ${v.status.error}`);
      pages[name] = v.page;
    }
    const view = await pages.package.evaluate(() => window.umbra.view?.() ?? null);
    const views = [''];
    if (orbit > 0 && view) for (let k = 1; k <= orbit; k++) views.push(`eye=${turned(view, (2 * Math.PI * k) / orbit).join(',')}`);
    const runs = Object.fromEntries(variants.map(([name]) => [name, []]));
    for (const v of views) {
      if (v) {
        // From each page's own first URL: appending to the current one would keep the previous
        // view's eye= first, which the viewer reads.
        for (const [name, p] of Object.entries(pages)) {
          await p.goto(`${variants.find(([n]) => n === name)[1]}&${v}`);
          await p.waitForFunction(() => document.body.dataset.state !== 'loading', null, { timeout: 600_000, polling: 250 });
        }
      }
      for (let i = 0; i < frames; i++) for (const [name, p] of Object.entries(pages)) runs[name].push(await draw(p));
    }
    for (const [name, r] of Object.entries(runs)) {
      const ms = r.map((x) => x.ms);
      const passes = {};
      for (const x of r) for (const [k, t] of Object.entries(x.passes)) passes[k] = (passes[k] || 0) + t / r.length;
      const lights = r.flatMap((x) => x.zpass);
      const z = lights.filter((s) => s !== null && s !== undefined).length;
      const p = Object.entries(passes).map(([k, t]) => `${k} ${t.toFixed(0)}`).join(', ');
      console.log(`${scene} ${name}: frame mean ${mean(ms).toFixed(0)} ms, min ${Math.min(...ms).toFixed(0)} ms; passes ${p || '(timing=0)'}; z-pass ${z}/${lights.length} lights; ${r[0].casters} casters`);
    }
    for (const p of Object.values(pages)) await p.close();
  }
} finally {
  await ctx.close();
  await new Promise((r) => server.close(r));
  await rm(tmp, { recursive: true, force: true });
}
