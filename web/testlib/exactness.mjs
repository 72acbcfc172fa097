// The viewer judged by the oracle: the browser draws the shadow-mask view
// (`mask=1`: white = lit, black = shadowed, as native umbra's lit mask), the mask is read back
// and written as a PNG, and `umbra verify --method vs-silhouette --external-mask PNG` compares
// it with the ray-traced reference of the same view under the oracle's own per-sample band —
// the same comparison, band and --explain as every native method gets, in one run that also
// verifies native vs-silhouette. Shared by test/browser.test.mjs and exact.mjs (the grid).
import { spawnSync } from 'node:child_process';
import { writeFile } from 'node:fs/promises';
import path from 'node:path';
import { encodePng } from './png.mjs';

/** Chromium flags shared by every launch: a headless, quiet, offline browser. */
export const COMMON_FLAGS = ['--headless', '--no-sandbox', '--disable-quic', '--no-first-run', '--disable-background-networking',
  '--disable-component-update', '--disable-sync'];

/** The two WebGL 2 implementations this machine can run, by the flags that select them. */
export const IMPLEMENTATIONS = {
  // SwiftShader (what a user without a GPU gets): ANGLE on SwiftShader's Vulkan, no GPU process features.
  swiftshader: ['--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
  // ANGLE on the system's EGL (Mesa llvmpipe here, the native renderer's rasteriser).
  egl: ['--use-angle=gl-egl', '--ignore-gpu-blocklist'],
  // WebGPU on SwiftShader's Vulkan (headless; needs a http://127.0.0.1 page): umbra-three's
  // WebGPU path (test/webgpu.test.mjs).
  webgpu: ['--enable-unsafe-webgpu', '--enable-features=Vulkan', '--use-vulkan=swiftshader', '--use-webgpu-adapter=swiftshader', '--disable-vulkan-surface'],
};

/**
 * The sub-pixel precision of WebGPU on SwiftShader, for the band: WebGPU reports none, and
 * SwiftShader's Vulkan device rasterizes with 4 bits (its subPixelPrecisionBits,
 * vk::SUBPIXEL_PRECISION_BITS), the SUBPIXEL_BITS its WebGL 2 context reports through ANGLE.
 */
export const WEBGPU_SUBPIXEL_BITS = 4;

/** Launches Chromium at `executablePath` with implementation `name` and a fresh profile under `tmp`. */
export async function launch(executablePath, name, tmp) {
  const { chromium } = await import('playwright-core');
  return chromium.launchPersistentContext(path.join(tmp, `profile-${name}`), {
    executablePath,
    headless: true,
    args: [...COMMON_FLAGS, ...IMPLEMENTATIONS[name]],
  });
}

/** Opens the viewer at `url`, waits until it is ready or failed (timeout in ms); returns page and status. */
export async function openViewer(ctx, url, timeout = 600_000) {
  const page = await ctx.newPage();
  const logs = [];
  page.on('console', (m) => logs.push(m.text()));
  page.on('pageerror', (e) => logs.push(String(e)));
  await page.goto(url);
  await page.waitForFunction(() => document.body.dataset.state !== 'loading', null, { timeout, polling: 250 });
  const status = await page.evaluate(() => ({ state: window.umbra.state, depth: window.umbra.depth, error: window.umbra.error, frameMs: window.umbra.frameMs, renderer: window.umbra.renderer, depthClamp: window.umbra.depthClamp, subpixelBits: window.umbra.subpixelBits, zpass: window.umbra.info?.().zpass ?? null, volumes: window.umbra.info?.().volumes ?? null, volumeCull: window.umbra.info?.().volumeCull ?? null, silhouettes: window.umbra.info?.().silhouettes ?? null, info: document.getElementById('info').textContent, message: document.getElementById('message').textContent, visible: getComputedStyle(document.getElementById('message')).display !== 'none' }));
  return { page, status, logs };
}

/** The canvas as RGBA8 rows, top row first (glReadPixels rows come bottom-up). */
export async function readCanvas(page) {
  const { w, h, px } = await page.evaluate(() => {
    const c = document.getElementById('canvas');
    const gl = c.getContext('webgl2');
    const out = new Uint8Array(c.width * c.height * 4);
    gl.readPixels(0, 0, c.width, c.height, gl.RGBA, gl.UNSIGNED_BYTE, out);
    // A string (latin1) crosses the page boundary far faster than an array of numbers.
    let s = '';
    for (let i = 0; i < out.length; i += 8192) s += String.fromCharCode.apply(null, out.subarray(i, i + 8192));
    return { w: c.width, h: c.height, px: s };
  });
  const bottomUp = Buffer.from(px, 'latin1');
  const rgba = new Uint8Array(w * h * 4);
  for (let y = 0; y < h; y++) rgba.set(bottomUp.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
  return { width: w, height: h, rgba };
}

/**
 * `umbra verify --method vs-silhouette --external-mask maskPng` for `scene` at `size`
 * (`WxH`), with `extra` flags (the view: --light, --eye, ...). Returns { native, browser }:
 * the two JSON rows (mismatches_outside_band, band_samples, ...), `explained`: the lines
 * `--explain` printed for the browser's mismatches outside the band (false shadow / false
 * light, pixel, triangle), `pixels` ("x,y" of each), and the counts of false shadow and
 * false light among them.
 */
export function judge(umbra, { scene, size, maskPng, extra = [], explain = 0, diff = null }) {
  const args = ['verify', '--scene', scene, '--method', 'vs-silhouette', '--size', size, '--external-mask', maskPng, '--json', '--explain', String(explain), ...extra];
  if (diff) args.push('--diff', diff);
  const r = spawnSync(umbra, args, { encoding: 'utf8', maxBuffer: 64 << 20 });
  // Exit status 1 = a method failed (the rows say which); anything else is an error.
  if (r.status !== 0 && r.status !== 1) throw new Error(`umbra ${args.join(' ')}: exit ${r.status}: ${r.stderr}`);
  const rows = JSON.parse(r.stdout);
  const native = rows.find((x) => x.method === 'vs-silhouette');
  const browser = rows.find((x) => x.method === maskPng);
  const explained = r.stderr.split('\n').filter((l) => l.startsWith(`${maskPng} `)).map((l) => l.slice(maskPng.length + 1));
  const falseShadow = explained.filter((l) => / false shadow /.test(l)).length;
  // The samples outside the band, as "x,y" (all of them when `explain` is at least their number).
  const pixels = explained.map((l) => / \((\d+), (\d+)\):/.exec(l)).filter(Boolean).map((m) => `${m[1]},${m[2]}`);
  return { native, browser, explained, pixels, falseShadow, falseLight: explained.length - falseShadow, stderr: r.stderr };
}

/**
 * Light `k`'s decision as the page's UmbraShadows drew it (window.umbra.readMask(k): rows
 * top-down, 255 lit / 0 shadowed), as a PNG at `maskPng` (white lit, black shadowed).
 */
export async function writeLightMask(page, k, width, height, maskPng) {
  const s = await page.evaluate((i) => window.umbra.readMask(i), k);
  if (typeof s !== 'string' || s.length !== width * height) throw new Error(`readMask(${k}) gave ${typeof s === 'string' ? s.length : s} values, expected ${width * height}`);
  const gray = Buffer.from(s, 'latin1');
  const rgba = new Uint8Array(4 * width * height);
  for (let i = 0; i < gray.length; i++) rgba.set([gray[i], gray[i], gray[i], 255], 4 * i);
  await writeFile(maskPng, encodePng(width, height, rgba));
}

/**
 * Draws the mask view of `base` (the viewer's URL, with `scene=` etc. in `query`) in `ctx` at
 * `width`x`height`, writes it to `maskPng` and judges it. Returns judge()'s result plus the
 * page status.
 */
export async function maskAgainstReference(ctx, umbra, { base, query, scene, width, height, maskPng, extra = [], explain = 1_000_000, diff = null }) {
  const { page, status, logs } = await openViewer(ctx, `${base}?size=${width}x${height}&mask=1&${query}`);
  try {
    if (status.state !== 'ready') throw new Error(`viewer failed: ${status.error}\n${logs.join('\n')}`);
    const { rgba } = await readCanvas(page);
    await writeFile(maskPng, encodePng(width, height, rgba));
  } finally {
    await page.close();
  }
  // The band of the browser's own rasterizer precision (the SUBPIXEL_BITS its context reports).
  const bits = Number.isInteger(status.subpixelBits) && status.subpixelBits >= 4 ? ['--subpixel-bits', String(status.subpixelBits)] : [];
  return { ...judge(umbra, { scene, size: `${width}x${height}`, maskPng, extra: [...extra, ...bits], explain, diff }), status };
}
