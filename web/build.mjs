// Builds the WebGL2 viewer into web/dist/ with esbuild.
//
// The shared shadow-volume shader code is NOT copied: the virtual module `umbra:vs-silhouette`
// is made here, at build time, from the native method's own files —
// crates/umbra-gl/src/methods/vs_silhouette/volume.frag.glsl,
// crates/umbra-gl/src/methods/shared/{multiplicity,depth}.glsl (001's reference-edge
// orientation, 003's Eq. 6 and the near-plane distance) — and from the two pieces of
// vs_silhouette/mod.rs that are not .glsl files: the GLSL ES 3.00 prelude
// (ShaderDialect::Essl300) and the UMBRA_CULLED define. The build fails, naming the file, if
// any of them cannot be found, so the viewer's arithmetic can never drift from the native
// method's. The viewer's own volume and orientation programs are in src/glsl/ (docs/web.md).
//
// Usage: node build.mjs [--outdir DIR]
import * as esbuild from 'esbuild';
import { readFile, mkdir, copyFile } from 'node:fs/promises';
import { fileURLToPath } from 'node:url';
import path from 'node:path';

const here = path.dirname(fileURLToPath(import.meta.url));
const methods = path.join(here, '..', 'crates', 'umbra-gl', 'src', 'methods');
const outdirArg = process.argv.indexOf('--outdir');
const outdir = outdirArg > 0 ? path.resolve(process.argv[outdirArg + 1]) : path.join(here, 'dist');

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

const vsSilhouettePlugin = {
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

export async function build(dir = outdir) {
  await mkdir(dir, { recursive: true });
  await esbuild.build({
    entryPoints: [path.join(here, 'src', 'main.js')],
    bundle: true,
    format: 'esm',
    target: 'es2020',
    outfile: path.join(dir, 'viewer.js'),
    plugins: [vsSilhouettePlugin],
    loader: { '.glsl': 'text' },
    logLevel: 'warning',
  });
  await copyFile(path.join(here, 'src', 'index.html'), path.join(dir, 'index.html'));
  return dir;
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  build().then((d) => console.log(`umbra web: built ${path.relative(process.cwd(), d) || '.'}`), (e) => {
    console.error(`umbra web: build failed: ${e.message}`);
    process.exit(1);
  });
}
