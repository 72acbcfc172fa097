// Builds umbra-three into umbra-three/dist/: one self-contained ES module (dist/index.js,
// `three` left as an import for the user's import map or bundler; every shader inlined) and
// umbra-geom's WebAssembly module beside it (dist/umbra_wasm.wasm, fetched relative to the
// module's URL). Users need no bundler.
//
// The shared shadow-volume shader code is NOT copied: the virtual module `umbra:vs-silhouette`
// is made here, at build time, from the native method's own files —
// crates/umbra-gl/src/methods/vs_silhouette/volume.frag.glsl,
// crates/umbra-gl/src/methods/shared/{multiplicity,depth}.glsl (001's reference-edge
// orientation, 003's Eq. 6 and the near-plane distance) — and from the two pieces of
// vs_silhouette/mod.rs that are not .glsl files: the GLSL ES 3.00 prelude
// (ShaderDialect::Essl300) and the UMBRA_CULLED define. The build fails, naming the file, if
// any of them cannot be found, so the browser's arithmetic can never drift from the native
// method's. The package's own programs are in src/webgl/glsl/ (docs/web.md).
//
// The WebGPU entry (dist/webgpu.js, `umbra-three/webgpu`) takes its WGSL the same way: the
// virtual module `umbra:wgsl` is umbra-wgpu's own shader files (crates/umbra-wgpu/src/shaders/:
// volume, multiplicity, orientation, cs_sides, transform, resolve), read at build time.
//
// Usage: node build.mjs [--outdir DIR]   (needs ../umbra-geom-wasm/umbra_wasm.wasm: node ../build-wasm.mjs)
import * as esbuild from 'esbuild';
import { readFile, mkdir, copyFile, access } from 'node:fs/promises';
import { fileURLToPath } from 'node:url';
import path from 'node:path';

const here = path.dirname(fileURLToPath(import.meta.url));
const methods = path.join(here, '..', '..', 'crates', 'umbra-gl', 'src', 'methods');
const wgslDir = path.join(here, '..', '..', 'crates', 'umbra-wgpu', 'src', 'shaders');

/** umbra-wgpu's WGSL files the WebGPU drawer uses, by the name src/webgpu/passes.js and rays.js read. */
export const WGSL_FILES = {
  volume: 'volume.wgsl',
  multiplicity: 'multiplicity.wgsl',
  orientation: 'orientation.wgsl',
  csSides: 'cs_sides.wgsl',
  transform: 'transform.wgsl',
  resolve: 'resolve.wgsl',
  rayBvh: 'ray_bvh.wgsl',
  receiverCell: 'receiver_cell.wgsl',
  cull: 'cull.wgsl',
};

/** esbuild plugin: the virtual module `umbra:wgsl` (umbra-wgpu's shader text, by name). */
export const wgslPlugin = {
  name: 'umbra-wgsl',
  setup(build) {
    build.onResolve({ filter: /^umbra:wgsl$/ }, (args) => ({ path: args.path, namespace: 'umbra-wgsl' }));
    build.onLoad({ filter: /.*/, namespace: 'umbra-wgsl' }, async () => {
      const out = {};
      const files = [];
      for (const [k, f] of Object.entries(WGSL_FILES)) {
        const file = path.join(wgslDir, f);
        files.push(file);
        try {
          out[k] = await readFile(file, 'utf8');
        } catch (e) {
          throw new Error(`${file}: ${e.message} (umbra-three's WebGPU path reads umbra-wgpu's shaders at build time)`);
        }
      }
      return { contents: `export default ${JSON.stringify(out)};`, loader: 'js', watchFiles: files };
    });
  },
};
export const WASM = path.join(here, '..', 'umbra-geom-wasm', 'umbra_wasm.wasm');

/** Rust string literal body -> text (only the escapes mod.rs uses). */
function unescapeRust(s) {
  return s.replace(/\\n/g, '\n').replace(/\\"/g, '"').replace(/\\\\/g, '\\');
}

/** The ES 3.00 prelude and the culled-vertex define, read out of vs_silhouette/mod.rs. */
export async function nativePieces() {
  const file = path.join(methods, 'vs_silhouette', 'mod.rs');
  const rs = await readFile(file, 'utf8');
  const prelude = rs.match(/ShaderDialect::Essl300\s*=>\s*\{[^}]*?concat!\(\s*"((?:[^"\\]|\\.)*)"/);
  const culled = rs.match(/"(#define UMBRA_CULLED (?:[^"\\]|\\.)*)"/);
  if (!prelude) throw new Error(`${file}: no ShaderDialect::Essl300 prelude literal found`);
  if (!culled) throw new Error(`${file}: no "#define UMBRA_CULLED ..." literal found`);
  return { essl300Prelude: unescapeRust(prelude[1]), culledDefine: unescapeRust(culled[1]), modRs: file };
}

/** Every shader source of the native method, by name. */
export async function nativeShaders() {
  const files = {
    volumeFrag: path.join(methods, 'vs_silhouette', 'volume.frag.glsl'),
    multiplicity: path.join(methods, 'shared', 'multiplicity.glsl'),
    depth: path.join(methods, 'shared', 'depth.glsl'),
  };
  const out = {};
  for (const [k, f] of Object.entries(files)) out[k] = await readFile(f, 'utf8');
  return { ...out, ...(await nativePieces()), files };
}

/** esbuild plugin: the virtual module `umbra:vs-silhouette` (the native shader text). */
export const vsSilhouettePlugin = {
  name: 'umbra-vs-silhouette',
  setup(build) {
    build.onResolve({ filter: /^umbra:vs-silhouette$/ }, (args) => ({ path: args.path, namespace: 'umbra' }));
    build.onLoad({ filter: /.*/, namespace: 'umbra' }, async () => {
      const s = await nativeShaders();
      const { files, modRs, ...sources } = s;
      return {
        contents: `export default ${JSON.stringify(sources)};`,
        loader: 'js',
        // Rebuild when the native sources change (esbuild --watch / serve).
        watchFiles: [...Object.values(files), modRs],
      };
    });
  },
};

/** esbuild options every bundle of the package's source needs (shader text inlined). */
export const sourceOptions = {
  bundle: true,
  format: 'esm',
  target: 'es2020',
  plugins: [vsSilhouettePlugin, wgslPlugin],
  loader: { '.glsl': 'text', '.wgsl': 'text' },
  logLevel: 'warning',
};

/** Copies umbra_wasm.wasm into `dir`, with a clear error when it has not been built. */
export async function copyWasm(dir) {
  try {
    await access(WASM);
  } catch {
    throw new Error(`${WASM} is missing: build it with node web/build-wasm.mjs (rustup target add wasm32-unknown-unknown once)`);
  }
  await copyFile(WASM, path.join(dir, 'umbra_wasm.wasm'));
}

export async function buildPackage(dir = path.join(here, 'dist')) {
  await mkdir(dir, { recursive: true });
  await esbuild.build({
    ...sourceOptions,
    entryPoints: [path.join(here, 'src', 'index.js')],
    outfile: path.join(dir, 'index.js'),
    external: ['three'],
  });
  // The WebGPU entry: three.js's WebGPU build and TSL stay imports (the user's import map or bundler).
  await esbuild.build({
    ...sourceOptions,
    entryPoints: [path.join(here, 'src', 'webgpu', 'index.js')],
    outfile: path.join(dir, 'webgpu.js'),
    external: ['three', 'three/webgpu', 'three/tsl'],
  });
  await copyWasm(dir);
  return dir;
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const i = process.argv.indexOf('--outdir');
  buildPackage(i > 0 ? path.resolve(process.argv[i + 1]) : undefined).then((d) => console.log(`umbra-three: built ${path.relative(process.cwd(), d) || '.'}`), (e) => {
    console.error(`umbra-three: build failed: ${e.message}`);
    process.exit(1);
  });
}
