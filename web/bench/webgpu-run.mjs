// `node bench/run.mjs --webgpu`: umbra-three's WebGPU path (umbra-three/webgpu in three.js's
// WebGPURenderer, bench/webgpu.html) against three.js WebGPURenderer's own 2048 shadow maps
// (point and directional light) and no shadows, on one WebGPU adapter (SwiftShader), with
// the WebGL 2 rows of bench/index.html (none, map2048, umbra) in a second Chromium on the
// same machine for reference (its own flags: testlib/exactness.mjs IMPLEMENTATIONS[--impl]).
// One interleaved run: per scene and size both pages are open, and at each view every row
// draws one warm-up frame, then one timed frame, row after row (WebGL rows, then WebGPU rows),
// so a change in the machine's load reaches every row alike.
//   WebGPU row: gpu = ms from the render call to device.queue.onSubmittedWorkDone() (the queue
//     idle before), cpu = ms of the render call itself (main thread, no wait inside);
//   WebGL row: frame = ms until a 1-pixel readPixels returned, cpu = ms of the render call.
// Then, with --passes 1 (the default), one more frame per view and WebGPU row with a timestamp
// query around each render and compute pass (bench/webgpu.js passes()): umbra's depth pass, its
// compute passes (transform, orientation, sides: one pass per light), its volume pass (the
// volumes' stencil fill and the mask), three.js's shadow-map passes and its main pass.
// Called by run.mjs (which parses the flags); not a test.
import { mkdir, rm, writeFile } from 'node:fs/promises';
import os from 'node:os';
import path from 'node:path';
import { createServer, listen } from '../serve.mjs';
import { launch } from '../testlib/exactness.mjs';

export const GPU_LABELS = {
  gpunone: 'WebGPU: three.js, no shadows',
  gpumap2048: 'WebGPU: PointLight shadow 2048',
  gpudir2048: 'WebGPU: DirectionalLight shadow 2048',
  gpuumbra: 'WebGPU: umbra-three, point light',
  gpuumbradir: 'WebGPU: umbra-three, directional light',
  gpunocull: 'WebGPU: umbra-three volumeCull off, point light',
  gpunoculldir: 'WebGPU: umbra-three volumeCull off, directional light',
  gpuzfail: 'WebGPU: umbra-three z-fail only, point light',
  gpurays: 'WebGPU: umbra-three ray-bvh, point light',
  gpuraysdir: 'WebGPU: umbra-three ray-bvh, directional light',
};
/** The rows of the WebGL 2 page this mode draws for reference. */
export const GL_ROWS = ['none', 'map2048', 'umbra'];
export const DEFAULT_MODES = [...GL_ROWS, ...Object.keys(GPU_LABELS)];
/** Each umbra row and the three.js map it is held against (same run, same light). */
const AGAINST = { gpuumbra: 'gpumap2048', gpuumbradir: 'gpudir2048', gpunocull: 'gpumap2048', gpunoculldir: 'gpudir2048', gpuzfail: 'gpumap2048', gpurays: 'gpumap2048', gpuraysdir: 'gpudir2048', umbra: 'map2048' };

/** Median, mean, nearest-rank p95, min of `ms`. */
function stats(ms) {
  const s = [...ms].sort((a, b) => a - b);
  const n = s.length;
  return { median: n % 2 ? s[(n - 1) / 2] : 0.5 * (s[n / 2 - 1] + s[n / 2]), mean: s.reduce((a, b) => a + b, 0) / n, p95: s[Math.min(n - 1, Math.ceil(0.95 * n) - 1)], min: s[0], n };
}

/** A frame's timestamped passes, grouped: umbra's depth, compute and volume passes (or its ray passes, method ray-bvh), three.js's shadow passes and main pass (the last it ran). */
function groupPasses(passes) {
  const g = { 'umbra depth': 0, 'umbra compute': 0, 'umbra volumes + mask': 0, 'three.js shadow maps': 0, 'three.js main pass': 0, 'passes in all': 0 };
  const three = passes.filter((p) => !p.label.startsWith('umbra')).sort((a, b) => a.at - b.at);
  for (const p of passes) {
    g['passes in all'] += p.ms;
    if (p.label === 'umbra depth') g['umbra depth'] += p.ms;
    else if (/^umbra light \d+ silhouettes$/.test(p.label)) g['umbra compute'] += p.ms;
    else if (/^umbra light \d+ volumes$/.test(p.label)) g['umbra volumes + mask'] += p.ms;
    else if (/^umbra (light \d+ rays|ray-bvh samples)$/.test(p.label)) g['umbra rays'] = (g['umbra rays'] || 0) + p.ms;
    else if (p.label.startsWith('umbra')) g['umbra, other passes'] = (g['umbra, other passes'] || 0) + p.ms;
  }
  three.forEach((p, i) => {
    g[i === three.length - 1 ? 'three.js main pass' : 'three.js shadow maps'] += p.ms;
  });
  return g;
}

export async function runWebGPU(o) {
  const { dist, scenes, sizes, modes, flyViews, frames, warmup, passFrames, shots, outFile, impl, flythrough, interpolate, repo, webDir, LABELS, fmt } = o;
  const label = (m) => GPU_LABELS[m] ?? `WebGL 2: ${LABELS[m]}`;
  const glModes = modes.filter((m) => !GPU_LABELS[m]);
  const gpuModes = modes.filter((m) => GPU_LABELS[m]);
  const chromium = process.env.UMBRA_CHROMIUM || '/usr/bin/chromium';
  const tmp = await (await import('node:fs/promises')).mkdtemp(path.join(os.tmpdir(), 'umbra-bench-webgpu-'));
  const mounts = [['/', webDir]];
  scenes.forEach((s, i) => mounts.push([`/scene${i}/`, path.dirname(s)]));
  if (dist) mounts.push(['/umbra-three/dist/', dist]);
  const server = createServer(mounts);
  const base = await listen(server);
  const browsers = {};
  const results = {
    date: new Date().toISOString(),
    command: `node bench/run.mjs ${process.argv.slice(2).join(' ')}`.trim(),
    machine: `${os.cpus().length} x ${os.cpus()[0]?.model}, ${(os.totalmem() / 2 ** 30).toFixed(0)} GiB, load average ${os.loadavg().map((l) => l.toFixed(2)).join(' ')} at the start`,
    browser: null,
    implementations: { webgl: glModes.length ? impl : null, webgpu: gpuModes.length ? 'webgpu' : null },
    adapters: {},
    views: flyViews,
    frames,
    warmup,
    runs: [],
  };
  const started = performance.now();
  try {
    if (glModes.length) browsers.gl = await launch(chromium, impl, tmp);
    if (gpuModes.length) browsers.gpu = await launch(chromium, 'webgpu', tmp);
    if (shots) await mkdir(shots, { recursive: true });
    for (const [i, scene] of scenes.entries()) {
      for (const size of sizes) {
        const name = path.basename(scene);
        const pages = {};
        const logs = [];
        for (const [kind, page] of [['gl', 'bench/'], ['gpu', 'bench/webgpu.html']]) {
          if (!browsers[kind]) continue;
          const p = await browsers[kind].newPage();
          p.on('console', (m) => logs.push(`${kind}: ${m.text()}`));
          p.on('pageerror', (e) => logs.push(`${kind}: ${e}`));
          await p.goto(`${base}${page}?model=/scene${i}/${encodeURIComponent(name)}&size=${size}`);
          pages[kind] = p;
        }
        const run = { scene: name, size, triangles: null, loadMs: {}, renderers: {}, first: {}, samples: Object.fromEntries(modes.map((m) => [m, []])), passes: Object.fromEntries(gpuModes.map((m) => [m, []])), views: [] };
        for (const [kind, p] of Object.entries(pages)) {
          await p.waitForFunction(() => window.bench && (window.bench.ready || window.bench.error), null, { timeout: 1_800_000, polling: 500 });
          const info = await p.evaluate(() => ({ userAgent: navigator.userAgent, error: window.bench.error, triangles: window.bench.triangles, renderer: window.bench.renderer, loadMs: window.bench.loadMs }));
          if (info.error) throw new Error(`${name} ${size} (${kind}): ${info.error}\n${logs.join('\n')}`);
          results.browser ??= info.userAgent.match(/(?:Headless)?Chrome\/[\d.]+/)?.[0] ?? info.userAgent;
          results.adapters[kind] = info.renderer;
          run.triangles = info.triangles;
          run.renderers[kind] = info.renderer;
          run.loadMs[kind] = info.loadMs;
        }
        const pageOf = (m) => (GPU_LABELS[m] ? pages.gpu : pages.gl);
        console.error(`${name} ${size}: ${run.triangles} triangles; ${Object.entries(run.renderers).map(([k, r]) => `${k}: ${r}`).join('; ')}`);
        for (const m of modes) {
          run.first[m] = await pageOf(m).evaluate((x) => window.bench.first(x), m);
          console.error(`  first frame ${m}: ${fmt(run.first[m])} ms`);
        }
        // One frame of row m: { frame (GPU: to onSubmittedWorkDone; GL: to the readPixels), cpu }.
        const frame = async (m) => {
          if (GPU_LABELS[m]) {
            const r = await pages.gpu.evaluate((x) => window.bench.frame(x), m);
            return { frame: r.gpu, cpu: r.cpu, umbraCpu: r.umbraCpu };
          }
          return pages.gl.evaluate((x) => window.bench.split(x), m);
        };
        let views;
        if (flyViews > 0) {
          const { file, keys } = await flythrough(scene);
          run.flythrough = { file: path.relative(repo, file), views: flyViews };
          views = interpolate(keys, flyViews).map((v) => ({ ...v, warmup: 1, frames: 1 }));
        } else {
          views = [{ eye: null, target: null, warmup, frames }];
        }
        for (const [v, view] of views.entries()) {
          if (view.eye) for (const p of Object.values(pages)) await p.evaluate(([e, t]) => window.bench.view(e, t), [view.eye, view.target]);
          const record = { eye: view.eye, target: view.target, rounds: [] };
          for (let r = 0; r < view.warmup + view.frames; r++) {
            const round = {};
            for (const m of modes) {
              round[m] = await frame(m);
              if (r >= view.warmup) run.samples[m].push(round[m]);
            }
            if (r >= view.warmup) record.rounds.push(round);
            console.error(`  view ${v + 1}/${views.length}, round ${r + 1}/${view.warmup + view.frames}${r < view.warmup ? ' (warm-up)' : ''}: ${modes.map((m) => `${m} ${fmt(round[m].frame)} (cpu ${fmt(round[m].cpu)})`).join(', ')}`);
          }
          if (passFrames > 0) {
            record.passes = {};
            for (const m of gpuModes) {
              for (let k = 0; k < passFrames; k++) {
                const p = await pages.gpu.evaluate((x) => window.bench.passes(x), m);
                run.passes[m].push({ gpu: p.gpu, groups: groupPasses(p.passes), passes: p.passes });
                (record.passes[m] ??= []).push(p);
              }
            }
            console.error(`  passes: ${gpuModes.map((m) => `${m} ${Object.entries(run.passes[m].at(-1).groups).filter(([, x]) => x > 0).map(([k, x]) => `${k} ${fmt(x)}`).join(' / ')}`).join('; ')}`);
          }
          for (const m of gpuModes.filter((x) => x.startsWith('gpuumbra') || x.startsWith('gpunocull') || x.startsWith('gpurays') || x === 'gpuzfail')) (record.info ??= {})[m] = await pages.gpu.evaluate((x) => window.bench.info(x), m);
          run.views.push(record);
        }
        run.summary = Object.fromEntries(modes.map((m) => [m, { frame: stats(run.samples[m].map((x) => x.frame)), cpu: stats(run.samples[m].map((x) => x.cpu)) }]));
        run.passSummary = Object.fromEntries(gpuModes.filter((m) => run.passes[m].length).map((m) => {
          const keys = [...new Set(run.passes[m].flatMap((x) => Object.keys(x.groups)))];
          const mean = (f) => run.passes[m].reduce((a, x) => a + (f(x) || 0), 0) / run.passes[m].length;
          return [m, { ...Object.fromEntries(keys.map((k) => [k, mean((x) => x.groups[k])])), 'frame (wall)': mean((x) => x.gpu) }];
        }));
        run.memory = {};
        for (const [kind, p] of Object.entries(pages)) run.memory[kind] = await p.evaluate(() => window.bench.memory());
        if (shots) {
          for (const m of modes) {
            const url = await pageOf(m).evaluate((x) => window.bench.shot(x), m);
            await writeFile(path.join(shots, `${name.replace(/\..*$/, '')}.${size}.${m}.png`), Buffer.from(url.split(',')[1], 'base64'));
          }
        }
        for (const p of Object.values(pages)) await p.close();
        results.runs.push(run);
        console.error(`  ${((performance.now() - started) / 60000).toFixed(1)} minutes so far`);
      }
    }
  } finally {
    for (const b of Object.values(browsers)) await b.close();
    server.close();
    await rm(tmp, { recursive: true, force: true });
  }
  results.minutes = (performance.now() - started) / 60000;
  results.loadAfter = os.loadavg();
  if (outFile) await writeFile(outFile, JSON.stringify(results, null, 1) + '\n');
  console.log(markdown(results, modes, label, fmt));
}

function markdown(r, modes, label, fmt) {
  const gpuModes = modes.filter((m) => GPU_LABELS[m]);
  const how = r.views > 0 ? `${r.views} fly-through views per scene, at each one warm-up and one timed frame per row, interleaved (median over the ${r.views} views)` : `${r.frames} frames per row after ${r.warmup} warm-up, interleaved`;
  const lines = [`${r.date.slice(0, 10)}, ${r.browser}; WebGPU rows: ${r.adapters.gpu ?? '-'}; WebGL 2 rows (${r.implementations.webgl ?? '-'}): ${r.adapters.gl ?? '-'}; ${r.machine}; load average ${r.loadAfter.map((l) => l.toFixed(2)).join(' ')} at the end; ${r.minutes.toFixed(1)} minutes; \`${r.command}\`; ${how}.`, ''];
  const table = (title, cell) => {
    lines.push(title, '', `| scene | size | ${modes.map(label).join(' | ')} |`, `| --- | --- |${modes.map(() => ' ---: |').join('')}`);
    for (const run of r.runs) lines.push(`| ${run.scene} | ${run.size} | ${modes.map((m) => cell(run, m)).join(' | ')} |`);
    lines.push('');
  };
  table('GPU frame, ms: median (mean, p95) (WebGPU: the render call to onSubmittedWorkDone; WebGL 2: to a 1-pixel readPixels):', (run, m) => `${fmt(run.summary[m].frame.median)} (${fmt(run.summary[m].frame.mean)}, ${fmt(run.summary[m].frame.p95)})`);
  table('Main thread (CPU), ms of the render call, no wait inside: median (mean, p95):', (run, m) => `${fmt(run.summary[m].cpu.median)} (${fmt(run.summary[m].cpu.mean)}, ${fmt(run.summary[m].cpu.p95)})`);
  const ours = Object.keys(AGAINST).filter((m) => modes.includes(m) && modes.includes(AGAINST[m]));
  if (ours.length) {
    lines.push('umbra against the 2048 map of the same light, same run (ratio of medians; GPU frame / main thread; below 1: umbra costs less):', '');
    lines.push(`| scene | size | ${ours.map((m) => `${label(m)} / ${label(AGAINST[m]).replace(/^WebG\w+ ?\d?: /, '')}`).join(' | ')} |`, `| --- | --- |${ours.map(() => ' ---: |').join('')}`);
    for (const run of r.runs) lines.push(`| ${run.scene} | ${run.size} | ${ours.map((m) => `${(run.summary[m].frame.median / run.summary[AGAINST[m]].frame.median).toFixed(2)} / ${(run.summary[m].cpu.median / run.summary[AGAINST[m]].cpu.median).toFixed(2)}`).join(' | ')} |`);
    lines.push('');
  }
  const withPasses = r.runs.filter((run) => Object.keys(run.passSummary || {}).length);
  if (withPasses.length) {
    const other = withPasses.some((run) => Object.values(run.passSummary).some((x) => x['umbra, other passes']));
    const rays = withPasses.some((run) => Object.values(run.passSummary).some((x) => x['umbra rays']));
    const keys = ['umbra depth', 'umbra compute', 'umbra volumes + mask', ...(rays ? ['umbra rays'] : []), ...(other ? ['umbra, other passes'] : []), 'three.js shadow maps', 'three.js main pass', 'passes in all', 'frame (wall)'];
    lines.push('Where the WebGPU frame goes: GPU ms per pass group (timestamp queries, one more frame per view, mean over the views):', '');
    lines.push(`| scene | size | row | ${keys.join(' | ')} |`, `| --- | --- | --- |${keys.map(() => ' ---: |').join('')}`);
    for (const run of withPasses) for (const m of gpuModes) if (run.passSummary[m]) lines.push(`| ${run.scene} | ${run.size} | ${label(m)} | ${keys.map((k) => (run.passSummary[m][k] ? fmt(run.passSummary[m][k]) : '-')).join(' | ')} |`);
    lines.push('');
  }
  table('First frame, ms (set-up included: the wasm, the casters\' preprocessing, pipelines; the model\'s loading excluded):', (run, m) => fmt(run.first[m]));
  const umbraRows = modes.filter((m) => m === 'umbra' || m.startsWith('gpuumbra') || m.startsWith('gpunocull') || m.startsWith('gpurays') || m === 'gpuzfail');
  if (umbraRows.length) {
    lines.push('GPU memory after the last frame, MiB (umbra.info.gpuBytes; in brackets against three.js\'s own vertex and index buffers of the model):', '');
    lines.push(`| scene | size | three.js buffers | ${umbraRows.map(label).join(' | ')} |`, `| --- | --- | ---: |${umbraRows.map(() => ' ---: |').join('')}`);
    const mb = (b) => (b / 2 ** 20).toFixed(1);
    for (const run of r.runs) {
      const three = (run.memory.gpu ?? run.memory.gl).three;
      lines.push(`| ${run.scene} | ${run.size} | ${mb(three)} | ${umbraRows.map((m) => {
        const b = (GPU_LABELS[m] ? run.memory.gpu : run.memory.gl)?.umbra[m];
        return b === undefined ? '-' : `${mb(b)} (${(b / three).toFixed(2)}x)`;
      }).join(' | ')} |`);
    }
  }
  return lines.join('\n');
}
