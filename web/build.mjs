// Builds the viewer (src/: a three.js page drawing umbra's shadows with the umbra-three
// package, umbra-three/src) into web/dist/ with esbuild: viewer.js (three.js and the package's
// source bundled, every shader inlined by the package's build options), index.html and
// umbra_wasm.wasm beside them (the package fetches it relative to its module).
//
// Usage: node build.mjs [--outdir DIR]
import * as esbuild from 'esbuild';
import { mkdir, copyFile } from 'node:fs/promises';
import { fileURLToPath } from 'node:url';
import path from 'node:path';
import { sourceOptions, copyWasm } from './umbra-three/build.mjs';

const here = path.dirname(fileURLToPath(import.meta.url));
const outdirArg = process.argv.indexOf('--outdir');
const outdir = outdirArg > 0 ? path.resolve(process.argv[outdirArg + 1]) : path.join(here, 'dist');

export async function build(dir = outdir) {
  await mkdir(dir, { recursive: true });
  await esbuild.build({
    ...sourceOptions,
    entryPoints: [path.join(here, 'src', 'main.js')],
    outfile: path.join(dir, 'viewer.js'),
  });
  await copyFile(path.join(here, 'src', 'index.html'), path.join(dir, 'index.html'));
  await copyWasm(dir);
  return dir;
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  build().then((d) => console.log(`umbra web: built ${path.relative(process.cwd(), d) || '.'}`), (e) => {
    console.error(`umbra web: build failed: ${e.message}`);
    process.exit(1);
  });
}
