// Frame times of umbra-three against what a three.js user has for shadows (a measurement,
// never a test): bench/index.html in headless Chromium, the shared scenes loaded by three.js's
// OBJLoader, each row drawn by the same page in one interleaved run:
//   none (no shadows), map1024 and map2048 (PointLight cube shadow maps), bvh (three-mesh-bvh
//   shadow rays in the fragment shader), umbra (the package).
// Per scene and size: every row's first frame (its set-up included: the BVH build, the
// package's wasm loading and preprocessing), then `--warmup` rounds, then `--frames` rounds
// of one frame per row in turn, so that a change in the machine's load reaches every row
// alike; mean and p95 (nearest rank) per row; then umbra's pass breakdown (umbra.timing,
// readPixels after every pass) over `--passes` more frames, apart from the timed ones.
//
//   node bench/run.mjs [--scenes A,B] [--sizes 1280x720,640x360] [--frames 3] [--warmup 1]
//                      [--passes 1] [--modes none,map1024,map2048,bvh,umbra]
//                      [--impl swiftshader|egl] [--out FILE.json] [--shots DIR]
//                      [--flythrough N | --orbit N [--move-light]] [--webgpu] [--dist DIR]
//   --scenes  mesh files (default: the three shared scenes in UMBRA_SCENES, default
//             ../shared/scenes beside the repository)
//   --out     the results as JSON (default: print only); the markdown table goes to stdout
//   --shots   a PNG of every row per scene and size, to check what was drawn
//   --dist DIR  serve the package from DIR (a `node umbra-three/build.mjs --outdir DIR` of
//             another tree, e.g. a commit's) instead of umbra-three/dist
//   --flythrough N  instead of the default view, N views along the scene's fly-through
//             (bench/<scene>.flythrough, the keyframes of `umbra bench --flythrough`,
//             interpolated with its uniform Catmull-Rom spline; the light stays umbra's
//             default): per view one warm-up frame per row, then one timed frame per row in
//             turn; the means are over the views; umbra's pass breakdown (--passes 1) is one
//             frame per view and umbra row
//   --orbit N  instead: N + 1 frames of a camera orbit about the view's target (one turn, frame
//             0 a warm-up), one frame per row in turn; per row the main-thread ms of its render
//             call (no GPU sync inside the span) and the frame's ms until a readPixels returned;
//             --move-light: the light also moves every frame (a small circle)
// Rows: none, map1024, map2048, bvh, umbra, umbranocull (the package with volumeCull off),
// umbraclamp / umbranoclamp (culled volumes always / never clamped: volumeClamp), each with
// cache: false (every frame drawn in full); umbracache and umbracachenocull (the package's
// defaults, cache on, with volumeCull on / off) and umbragpu (unculled, silhouettes: 'gpu':
// a GPU's defaults) for the orbit.
//   --webgpu  instead: the WebGPU comparison (bench/webgpu-run.mjs, bench/webgpu.html): on one
//             WebGPU adapter (SwiftShader; testlib/exactness.mjs IMPLEMENTATIONS.webgpu, a
//             http://127.0.0.1 page), three.js's WebGPURenderer with no shadows (gpunone), with
//             its 2048 PointLight map (gpumap2048) and 2048 DirectionalLight map (gpudir2048),
//             and umbra-three/webgpu with the point light (gpuumbra) and the directional one
//             (gpuumbradir), both culled on the GPU (its default), with volumeCull: false
//             (gpunocull, gpunoculldir), with zpass: false (gpuzfail) and with its method 'ray-bvh'
//             (gpurays, gpuraysdir); beside them, in a second Chromium with the --impl flags,
//             the WebGL 2 rows none, map2048 and umbra for reference. Default --modes: all 13. Each frame timed twice: the GPU
//             frame (WebGPU: from the render call to the queue's onSubmittedWorkDone; WebGL: to
//             a 1-pixel readPixels) and the main thread's ms in the render call; medians,
//             ratios against the 2048 map of the same light; with --passes 1, one more frame
//             per view and WebGPU row with a timestamp query around every pass (umbra's depth,
//             compute and volume or ray passes, three.js's shadow and main passes). With
//             --flythrough N along the fly-through as above, else --warmup and --frames rounds
//             of the default view. No --orbit.
//             node bench/run.mjs --webgpu --flythrough 4 --sizes 640x360,1280x720 --out r.json
// Needs /usr/bin/chromium (or UMBRA_CHROMIUM), `npm ci` in web/ and the package built.
import { mkdtemp, mkdir, rm, writeFile } from 'node:fs/promises';
import { existsSync } from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { createServer, listen } from '../serve.mjs';
import { launch } from '../testlib/exactness.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const webDir = path.join(here, '..');
const repo = path.join(webDir, '..');
const arg = (name, dflt) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? process.argv[i + 1] : dflt;
};
const scenesDir = process.env.UMBRA_SCENES || path.join(repo, '..', 'shared', 'scenes');
const scenes = arg('--scenes', ['crytek-sponza', 'conference', 'sibenik'].map((s) => path.join(scenesDir, `${s}.obj.gz`)).join(',')).split(',').map((s) => path.resolve(s));
const sizes = arg('--sizes', '1280x720,640x360').split(',');
const frames = Number(arg('--frames', '3'));
const warmup = Number(arg('--warmup', '1'));
const passFrames = Number(arg('--passes', '1'));
const webgpu = process.argv.includes('--webgpu');
const { GPU_LABELS, DEFAULT_MODES: WEBGPU_MODES, runWebGPU } = await import('./webgpu-run.mjs');
const modes = arg('--modes', webgpu ? WEBGPU_MODES.join(',') : 'none,map1024,map2048,bvh,umbra').split(',');
const flyViews = Number(arg('--flythrough', '0'));
const orbitFrames = Number(arg('--orbit', '0'));
const moveLight = process.argv.includes('--move-light');
const impl = arg('--impl', 'swiftshader');
const outFile = arg('--out', null);
const shots = arg('--shots', null);
const dist = arg('--dist', null) && path.resolve(arg('--dist', null));
const LABELS = { umbragpu: 'umbra-three (cache), unculled, GPU silhouettes', umbracache: 'umbra-three (cache)', umbracachenocull: 'umbra-three (cache), volumeCull off', none: 'three.js, no shadows', map1024: 'PointLight shadow 1024', map2048: 'PointLight shadow 2048', bvh: 'three-mesh-bvh shadow rays', umbra: 'umbra-three', umbranocull: 'umbra-three, volumeCull off', umbraclamp: 'umbra-three, always clamped', umbranoclamp: 'umbra-three, never clamped', umbramrt: 'umbra-three, positions from the depth pass' };
const UMBRA_ROWS = ['umbra', 'umbranocull', 'umbraclamp', 'umbranoclamp', 'umbramrt', 'umbracache', 'umbracachenocull', 'umbragpu'];

/** The fly-through keyframes of `scene` (bench/<name>.flythrough: eye xyz, target xyz per line). */
async function flythrough(scene) {
  const name = path.basename(scene).replace(/\..*$/, '').replace(/^crytek-/, '');
  const file = path.join(repo, 'bench', `${name}.flythrough`);
  const { readFile } = await import('node:fs/promises');
  const keys = (await readFile(file, 'utf8')).split('\n').map((l) => l.split('#')[0].trim()).filter(Boolean).map((l) => {
    const v = l.split(/[\s,]+/).map(Number);
    if (v.length !== 6 || !v.every(Number.isFinite)) throw new Error(`${file}: bad keyframe ${l}`);
    return { eye: v.slice(0, 3), target: v.slice(3) };
  });
  return { file, keys };
}

/** crates/umbra-cli/src/bench/flythrough.rs interpolate(): `frames` views on the uniform Catmull-Rom spline. */
function interpolate(keys, frames) {
  const n = keys.length;
  const cr = (p0, p1, p2, p3, u) => [0, 1, 2].map((k) => 0.5 * (2 * p1[k] + (-p0[k] + p2[k]) * u + (2 * p0[k] - 5 * p1[k] + 4 * p2[k] - p3[k]) * u * u + (-p0[k] + 3 * p1[k] - 3 * p2[k] + p3[k]) * u * u * u));
  const reflect = (a, b) => ({ eye: [0, 1, 2].map((k) => 2 * a.eye[k] - b.eye[k]), target: [0, 1, 2].map((k) => 2 * a.target[k] - b.target[k]) });
  return Array.from({ length: frames }, (_, f) => {
    if (n === 1 || frames === 1) return keys[0];
    const t = (f * (n - 1)) / (frames - 1);
    const seg = Math.min(Math.floor(t), n - 2);
    const u = t - seg;
    if (u === 0) return keys[seg];
    if (u === 1) return keys[seg + 1];
    const k0 = seg === 0 ? reflect(keys[0], keys[1]) : keys[seg - 1];
    const [k1, k2] = [keys[seg], keys[seg + 1]];
    const k3 = seg + 2 < n ? keys[seg + 2] : reflect(keys[n - 1], keys[n - 2]);
    return { eye: cr(k0.eye, k1.eye, k2.eye, k3.eye, u), target: cr(k0.target, k1.target, k2.target, k3.target, u) };
  });
}
for (const m of modes) {
  if (GPU_LABELS[m] && !webgpu) throw new Error(`--modes: row ${m} is a WebGPU row: it needs --webgpu`);
  if (!LABELS[m] && !GPU_LABELS[m]) throw new Error(`--modes: unknown row ${m} (${[...Object.keys(LABELS), ...Object.keys(GPU_LABELS)].join(', ')})`);
}
for (const s of scenes) if (!existsSync(s)) throw new Error(`${s}: no such scene file`);

if (webgpu) {
  // The WebGPU comparison (bench/webgpu-run.mjs): its own pages, browsers and tables.
  if (orbitFrames > 0) throw new Error('--webgpu: --orbit is not supported; use --flythrough N or the default view');
  await runWebGPU({ dist, scenes, sizes, modes, flyViews, frames, warmup, passFrames, shots, outFile, impl, flythrough, interpolate, repo, webDir, LABELS, fmt: (ms) => (ms >= 100 ? ms.toFixed(0) : ms.toFixed(1)).replace(/\B(?=(\d{3})+(?!\d))/g, ',') });
  process.exit(0);
}

/** Mean and nearest-rank p95 of `ms`. */
function summary(ms) {
  const s = [...ms].sort((a, b) => a - b);
  return { mean: s.reduce((a, b) => a + b, 0) / s.length, p95: s[Math.min(s.length - 1, Math.ceil(0.95 * s.length) - 1)], min: s[0], n: s.length };
}

const tmp = await mkdtemp(path.join(os.tmpdir(), 'umbra-bench-three-'));
const mounts = [['/', webDir]];
scenes.forEach((s, i) => mounts.push([`/scene${i}/`, path.dirname(s)]));
if (dist) mounts.push(['/umbra-three/dist/', dist]);
const server = createServer(mounts);
const base = await listen(server);
const browser = await launch(process.env.UMBRA_CHROMIUM || '/usr/bin/chromium', impl, tmp);
const results = {
  date: new Date().toISOString(),
  command: `node bench/run.mjs ${process.argv.slice(2).join(' ')}`.trim(),
  machine: `${os.cpus().length} x ${os.cpus()[0]?.model}, ${(os.totalmem() / 2 ** 30).toFixed(0)} GiB, load average ${os.loadavg().map((l) => l.toFixed(2)).join(' ')} at the start`,
  browser: null,
  implementation: impl,
  frames,
  warmup,
  runs: [],
};
const fmt = (ms) => (ms >= 100 ? ms.toFixed(0) : ms.toFixed(1)).replace(/\B(?=(\d{3})+(?!\d))/g, ',');
try {
  if (shots) await mkdir(shots, { recursive: true });
  for (const [i, scene] of scenes.entries()) {
    for (const size of sizes) {
      const name = path.basename(scene);
      const page = await browser.newPage();
      const logs = [];
      page.on('console', (m) => logs.push(m.text()));
      page.on('pageerror', (e) => logs.push(String(e)));
      const started = performance.now();
      await page.goto(`${base}bench/?model=/scene${i}/${encodeURIComponent(name)}&size=${size}`);
      await page.waitForFunction(() => window.bench && (window.bench.ready || window.bench.error), null, { timeout: 1_800_000, polling: 500 });
      const info = await page.evaluate(() => ({ userAgent: navigator.userAgent, error: window.bench.error, triangles: window.bench.triangles, renderer: window.bench.renderer, loadMs: window.bench.loadMs }));
      results.browser ??= info.userAgent.match(/(?:Headless)?Chrome\/[\d.]+/)?.[0] ?? info.userAgent;
      if (info.error) throw new Error(`${name} ${size}: ${info.error}\n${logs.join('\n')}`);
      const run = { scene: name, size, triangles: info.triangles, renderer: info.renderer, loadMs: info.loadMs, first: {}, ms: {}, summary: {} };
      console.error(`${name} ${size}: loaded in ${(performance.now() - started).toFixed(0)} ms (${info.triangles} triangles, ${info.renderer})`);
      for (const mode of modes) {
        run.first[mode] = await page.evaluate((m) => window.bench.first(m), mode);
        run.ms[mode] = [];
        console.error(`  first frame ${mode}: ${fmt(run.first[mode])} ms`);
      }
      if (flyViews > 0) {
        // Along the fly-through: per view a warm-up frame per row, then a timed one per row.
        const { file, keys } = await flythrough(scene);
        run.flythrough = { file: path.relative(repo, file), views: flyViews };
        run.views = [];
        for (const [v, view] of interpolate(keys, flyViews).entries()) {
          await page.evaluate(([e, t]) => window.bench.view(e, t), [view.eye, view.target]);
          for (const mode of modes) await page.evaluate((m) => window.bench.frame(m), mode);
          const round = {};
          for (const mode of modes) {
            round[mode] = await page.evaluate((m) => window.bench.frame(m), mode);
            run.ms[mode].push(round[mode]);
          }
          const drawn = {};
          for (const mode of modes.filter((m) => UMBRA_ROWS.includes(m))) {
            const info = await page.evaluate((m) => window.bench.info(m), mode);
            drawn[mode] = { zpass: info.zpass, volumes: info.volumes };
            if (passFrames > 0) drawn[mode].passes = (await page.evaluate(([n, m]) => window.bench.passes(n, m), [passFrames, mode])).passes;
          }
          run.views.push({ eye: view.eye, target: view.target, ms: round, drawn });
          console.error(`  view ${v + 1}/${flyViews}: ${modes.map((m) => `${m} ${fmt(round[m])}`).join(', ')}; ${Object.entries(drawn).map(([m, d]) => `${m} ${JSON.stringify(d.volumes)} zpass ${JSON.stringify(d.zpass)}`).join('; ')}`);
        }
      }
      run.memory = await page.evaluate(() => window.bench.memory());
      console.error(`  GPU bytes: three.js's buffers ${run.memory.three}; ${Object.entries(run.memory.umbra).map(([m, b]) => `${m} ${b} (${(b / run.memory.three).toFixed(2)}x)`).join(', ')}`);
      if (orbitFrames > 0) {
        run.orbit = { frames: orbitFrames, moveLight, rows: Object.fromEntries(modes.map((m) => [m, []])) };
        for (let f = 0; f <= orbitFrames; f++) {
          const round = {};
          for (const mode of modes) {
            round[mode] = await page.evaluate(([m, i, n, l]) => window.bench.orbit(m, i, n, l), [mode, f, orbitFrames, moveLight]);
            if (f > 0) run.orbit.rows[mode].push(round[mode]);
          }
          if (f % 10 === 0 || process.env.UMBRA_BENCH_VERBOSE) console.error(`  orbit ${f}/${orbitFrames}: ${modes.map((m) => `${m} ${fmt(round[m].cpu)} / ${fmt(round[m].frame)}${round[m].parts ? ` ${JSON.stringify(round[m].parts)}` : ''}`).join(', ')}`);
        }
        run.orbit.summary = Object.fromEntries(modes.map((m) => {
          const rows = run.orbit.rows[m];
          return [m, { cpu: summary(rows.map((x) => x.cpu)), frame: summary(rows.map((x) => x.frame)), reused: rows.filter((x) => x.reused).length, cached: rows.reduce((a, x) => a + (x.cached || 0), 0) }];
        }));
      }
      for (let r = 0; flyViews === 0 && orbitFrames === 0 && r < warmup + frames; r++) {
        const round = {};
        for (const mode of modes) {
          round[mode] = await page.evaluate((m) => window.bench.frame(m), mode);
          if (r >= warmup) run.ms[mode].push(round[mode]);
        }
        console.error(`  round ${r + 1}/${warmup + frames}${r < warmup ? ' (warm-up)' : ''}: ${modes.map((m) => `${m} ${fmt(round[m])}`).join(', ')}`);
      }
      for (const mode of modes) run.summary[mode] = run.ms[mode].length ? summary(run.ms[mode]) : null;
      if (flyViews > 0) {
        // The pass breakdown: the mean over the views.
        for (const mode of modes.filter((m) => UMBRA_ROWS.includes(m))) {
          const sum = {};
          for (const v of run.views) for (const [k, x] of Object.entries(v.drawn[mode].passes || {})) sum[k] = (sum[k] || 0) + x / run.views.length;
          (run.flyPasses ??= {})[mode] = sum;
        }
      } else if (modes.includes('umbra') && passFrames > 0 && orbitFrames === 0) {
        const p = await page.evaluate((n) => window.bench.passes(n), passFrames);
        run.passes = p.passes;
        run.umbraInfo = p.info;
        console.error(`  umbra passes: ${Object.entries(p.passes).map(([k, v]) => `${k} ${fmt(v)}`).join(', ')}`);
      }
      if (shots) {
        for (const mode of modes) {
          const url = await page.evaluate((m) => window.bench.shot(m), mode);
          await writeFile(path.join(shots, `${name.replace(/\..*$/, '')}.${size}.${mode}.png`), Buffer.from(url.split(',')[1], 'base64'));
        }
      }
      await page.close();
      results.runs.push(run);
    }
  }
} finally {
  await browser.close();
  server.close();
  await rm(tmp, { recursive: true, force: true });
}

if (outFile) await writeFile(outFile, JSON.stringify(results, null, 1) + '\n');
console.log(markdown(results));

/** The results as markdown tables: frame times, first frames, ratios, umbra's passes. */
function markdown(r) {
  if (orbitFrames > 0) return orbitMarkdown(r);
  const how = flyViews > 0 ? `${flyViews} fly-through views, one frame per row and view after one warm-up frame per row and view, interleaved` : `${r.frames} frames per row after ${r.warmup} warm-up, interleaved`;
  const lines = [`${r.date.slice(0, 10)}, ${r.browser} (${r.implementation}), ${r.machine}; \`${r.command}\`; ${how}.`, ''];
  lines.push(`Mean ms per frame (p95 in brackets):`, '');
  lines.push(`| scene | size | ${modes.map((m) => LABELS[m]).join(' | ')} |`, `| --- | --- |${modes.map(() => ' ---: |').join('')}`);
  for (const run of r.runs) lines.push(`| ${run.scene} | ${run.size} | ${modes.map((m) => `${fmt(run.summary[m].mean)} (${fmt(run.summary[m].p95)})`).join(' | ')} |`);
  lines.push('', 'First frame, ms (set-up included: BVH build, wasm loading and preprocessing; the model\'s loading excluded):', '');
  lines.push(`| scene | size | ${modes.map((m) => LABELS[m]).join(' | ')} |`, `| --- | --- |${modes.map(() => ' ---: |').join('')}`);
  for (const run of r.runs) lines.push(`| ${run.scene} | ${run.size} | ${modes.map((m) => fmt(run.first[m])).join(' | ')} |`);
  if (modes.includes('umbra')) {
    const against = ['map2048', 'bvh', 'umbranocull'].filter((m) => modes.includes(m));
    if (against.length) {
      lines.push('', 'Ratios of mean frame times (below 1: the package is faster):', '');
      lines.push(`| scene | size | ${against.map((m) => `umbra-three / ${LABELS[m]}`).join(' | ')} |`, `| --- | --- |${against.map(() => ' ---: |').join('')}`);
      for (const run of r.runs) lines.push(`| ${run.scene} | ${run.size} | ${against.map((m) => (run.summary.umbra.mean / run.summary[m].mean).toFixed(2)).join(' | ')} |`);
    }
    const fly = r.runs.filter((run) => run.flyPasses);
    if (fly.length) {
      const rows = UMBRA_ROWS.filter((m) => modes.includes(m));
      const keys = [...new Set(fly.flatMap((run) => rows.flatMap((m) => Object.keys(run.flyPasses[m] || {}))))];
      lines.push('', 'Pass by pass along the fly-through (mean over the views, umbra.timing = true), ms:', '');
      lines.push(`| scene | size | row | ${keys.join(' | ')} |`, `| --- | --- | --- |${keys.map(() => ' ---: |').join('')}`);
      for (const run of fly) for (const m of rows) lines.push(`| ${run.scene} | ${run.size} | ${LABELS[m]} | ${keys.map((k) => (run.flyPasses[m]?.[k] === undefined ? '-' : fmt(run.flyPasses[m][k]))).join(' | ')} |`);
      lines.push('', 'What the volumes drew along the fly-through (sum over the views: triangles / silhouette edge records; views culled; views counted z-pass):', '');
      lines.push(`| scene | size | ${rows.map((m) => LABELS[m]).join(' | ')} |`, `| --- | --- |${rows.map(() => ' --- |').join('')}`);
      for (const run of fly) {
        lines.push(`| ${run.scene} | ${run.size} | ${rows.map((m) => {
          const vs = run.views.map((v) => v.drawn[m]);
          const sum = (f) => vs.reduce((a, d) => a + d.volumes.reduce((b, l) => b + f(l), 0), 0);
          return `${sum((l) => l.triangles).toLocaleString('en')} / ${sum((l) => l.edges).toLocaleString('en')}; ${vs.filter((d) => d.volumes.every((l) => l.culled)).length} of ${vs.length} culled; ${vs.filter((d) => d.zpass.every((z) => z !== null)).length} z-pass`;
        }).join(' | ')} |`);
      }
    }
    const names = [...new Set(r.runs.flatMap((run) => Object.keys(run.passes || {})))];
    if (names.length) {
      lines.push('', 'umbra-three\'s frame pass by pass (umbra.timing = true: a readPixels after each pass), ms:', '');
      lines.push(`| scene | size | ${names.join(' | ')} |`, `| --- | --- |${names.map(() => ' ---: |').join('')}`);
      for (const run of r.runs) lines.push(`| ${run.scene} | ${run.size} | ${names.map((n) => (run.passes?.[n] === undefined ? '-' : fmt(run.passes[n]))).join(' | ')} |`);
    }
  }
  return [...lines, ...memoryLines(r)].join('\n');
}

/** The orbit's tables: main-thread ms of the render call and frame ms, per row; ratios against map2048. */
function orbitMarkdown(r) {
  const lines = [`${r.date.slice(0, 10)}, ${r.browser} (${r.implementation}), ${r.machine}; \`${r.command}\`; ${orbitFrames} frames of a camera orbit (one turn about the view's target) after one warm-up frame, one frame per row in turn; the light ${moveLight ? 'moving every frame' : 'still'}.`, ''];
  lines.push('Main-thread ms of the render call, no GPU sync inside (mean, p95 in brackets) / ms until the frame was read back (mean):', '');
  lines.push(`| scene | size | ${modes.map((m) => LABELS[m]).join(' | ')} |`, `| --- | --- |${modes.map(() => ' ---: |').join('')}`);
  for (const run of r.runs) lines.push(`| ${run.scene} | ${run.size} | ${modes.map((m) => `${fmt(run.orbit.summary[m].cpu.mean)} (${fmt(run.orbit.summary[m].cpu.p95)}) / ${fmt(run.orbit.summary[m].frame.mean)}`).join(' | ')} |`);
  const ours = modes.filter((m) => UMBRA_ROWS.includes(m));
  if (modes.includes('map2048') && ours.length) {
    lines.push('', 'Ratios against three.js\'s 2048 point-light map (main thread; frame), below 1: umbra costs less:', '');
    lines.push(`| scene | size | ${ours.map((m) => LABELS[m]).join(' | ')} |`, `| --- | --- |${ours.map(() => ' ---: |').join('')}`);
    for (const run of r.runs) {
      const s = run.orbit.summary;
      lines.push(`| ${run.scene} | ${run.size} | ${ours.map((m) => `${(s[m].cpu.mean / s.map2048.cpu.mean).toFixed(2)}; ${(s[m].frame.mean / s.map2048.frame.mean).toFixed(2)}`).join(' | ')} |`);
    }
    lines.push('', 'Silhouettes kept (casters x lights, summed over the frames) and frames reused:', '');
    lines.push(`| scene | size | ${ours.map((m) => LABELS[m]).join(' | ')} |`, `| --- | --- |${ours.map(() => ' ---: |').join('')}`);
    for (const run of r.runs) lines.push(`| ${run.scene} | ${run.size} | ${ours.map((m) => `${run.orbit.summary[m].cached} kept, ${run.orbit.summary[m].reused} reused`).join(' | ')} |`);
  }
  return [...lines, ...memoryLines(r)].join('\n');
}

/** GPU bytes per run: three.js's vertex and index buffers against each umbra row's info.gpuBytes. */
function memoryLines(r) {
  const runs = r.runs.filter((run) => run.memory && Object.keys(run.memory.umbra).length);
  if (!runs.length) return [];
  const rows = [...new Set(runs.flatMap((run) => Object.keys(run.memory.umbra)))];
  const mb = (b) => (b / 2 ** 20).toFixed(1);
  const lines = ['', 'GPU memory after the last frame, MiB (umbra.info.gpuBytes; in brackets: against three.js\'s own vertex and index buffers of the model):', ''];
  lines.push(`| scene | size | three.js buffers | ${rows.map((m) => LABELS[m]).join(' | ')} |`, `| --- | --- | ---: |${rows.map(() => ' ---: |').join('')}`);
  for (const run of runs) lines.push(`| ${run.scene} | ${run.size} | ${mb(run.memory.three)} | ${rows.map((m) => (run.memory.umbra[m] === undefined ? '-' : `${mb(run.memory.umbra[m])} (${(run.memory.umbra[m] / run.memory.three).toFixed(2)}x)`)).join(' | ')} |`);
  return lines;
}
