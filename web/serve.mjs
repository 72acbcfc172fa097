// A tiny static file server for the viewer, bound to 127.0.0.1 only.
//
// Serves read-only files from a few mounted directories (by default web/dist at "/" and an
// export at "/scene/") and NEVER anything outside them: the URL path is percent-decoded once,
// any "..", "." or empty-after-decoding segment, backslash or NUL is refused (400), and the
// file's REAL path (symlinks resolved) must lie inside the mount's real path (403) — so
// "/../x", "/%2e%2e/x", "//etc/passwd" and a symlink pointing out of the root all fail.
// Only GET and HEAD; directories serve their index.html.
//
// Usage: node serve.mjs [--port N] [--root DIR] [--scene DIR]   (port 0: any free port)
import http from 'node:http';
import { createReadStream } from 'node:fs';
import { realpath, stat } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.json': 'application/json',
  '.bin': 'application/octet-stream',
  '.png': 'image/png',
  '.css': 'text/css; charset=utf-8',
  '.wasm': 'application/wasm',
};

/**
 * Resolves a request path to a file inside one of `mounts` ([[urlPrefix, dir], ...], longest
 * prefix first), or returns an HTTP status explaining why not.
 */
export async function resolveRequest(mounts, rawPath) {
  const q = rawPath.indexOf('?');
  const p = q >= 0 ? rawPath.slice(0, q) : rawPath;
  if (!p.startsWith('/')) return { status: 400 };
  let segments;
  try {
    segments = p.split('/').slice(1).map((s) => decodeURIComponent(s));
  } catch {
    return { status: 400 };
  }
  // Decoded segments must be plain names: no traversal, no separators smuggled in encoded.
  for (let i = 0; i < segments.length; i++) {
    const s = segments[i];
    const last = i === segments.length - 1;
    if (s === '..' || s === '.' || s.includes('/') || s.includes('\\') || s.includes('\0') || (s === '' && !last)) return { status: 400 };
  }
  const rel = segments.join('/');
  for (const [prefix, dir] of mounts) {
    const pre = prefix.replace(/^\/+|\/+$/g, '');
    if (pre && rel !== pre && !rel.startsWith(pre + '/')) continue;
    const inner = pre ? rel.slice(pre.length).replace(/^\//, '') : rel;
    let root;
    try {
      root = await realpath(dir);
    } catch {
      return { status: 404 };
    }
    let file = path.join(root, ...inner.split('/').filter(Boolean));
    let real;
    try {
      real = await realpath(file);
      if ((await stat(real)).isDirectory()) {
        file = path.join(real, 'index.html');
        real = await realpath(file);
      }
    } catch {
      return { status: 404 };
    }
    if (real !== root && !real.startsWith(root + path.sep)) return { status: 403 };
    const s = await stat(real);
    if (!s.isFile()) return { status: 404 };
    return { status: 200, file: real, size: s.size };
  }
  return { status: 404 };
}

/** An http.Server for `mounts` (not yet listening). */
export function createServer(mounts) {
  const sorted = [...mounts].sort((a, b) => b[0].length - a[0].length);
  return http.createServer(async (req, res) => {
    if (req.method !== 'GET' && req.method !== 'HEAD') {
      res.writeHead(405, { Allow: 'GET, HEAD' }).end();
      return;
    }
    const r = await resolveRequest(sorted, req.url || '/');
    if (r.status !== 200) {
      res.writeHead(r.status, { 'Content-Type': 'text/plain' }).end(`${r.status}\n`);
      return;
    }
    res.writeHead(200, {
      'Content-Type': TYPES[path.extname(r.file)] || 'application/octet-stream',
      'Content-Length': r.size,
      'Cache-Control': 'no-store',
    });
    if (req.method === 'HEAD') return res.end();
    createReadStream(r.file).on('error', () => res.destroy()).pipe(res);
  });
}

/** Listens on 127.0.0.1:port (0 = any free port); resolves to the base URL. */
export function listen(server, port = 0) {
  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(port, '127.0.0.1', () => resolve(`http://127.0.0.1:${server.address().port}/`));
  });
}

if (process.argv[1] === fileURLToPath(import.meta.url)) {
  const here = path.dirname(fileURLToPath(import.meta.url));
  const arg = (name, dflt) => {
    const i = process.argv.indexOf(name);
    return i > 0 ? process.argv[i + 1] : dflt;
  };
  const mounts = [['/', path.resolve(arg('--root', path.join(here, 'dist')))], ['/scene/', path.resolve(arg('--scene', path.join(here, 'scene')))]];
  const server = createServer(mounts);
  listen(server, Number(arg('--port', '8080'))).then((url) => {
    console.log(`umbra web: serving ${mounts[0][1]} at ${url} and ${mounts[1][1]} at ${url}scene/ (Ctrl-C stops)`);
  }, (e) => {
    console.error(`umbra web: cannot listen: ${e.message}`);
    process.exit(1);
  });
}
