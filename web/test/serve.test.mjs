// web/serve.mjs never serves outside its roots: "..", percent-encoded dots,
// absolute paths, backslashes, NUL, symlinks out of the root. Run: node --test test/
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtemp, mkdir, writeFile, symlink, rm } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import http from 'node:http';
import { createServer, listen } from '../serve.mjs';

let dir, server, base;

before(async () => {
  dir = await mkdtemp(path.join(tmpdir(), 'umbra-serve-'));
  await mkdir(path.join(dir, 'root', 'sub'), { recursive: true });
  await mkdir(path.join(dir, 'scene'), { recursive: true });
  await writeFile(path.join(dir, 'root', 'index.html'), 'INDEX');
  await writeFile(path.join(dir, 'root', 'sub', 'a b.txt'), 'SPACED');
  await writeFile(path.join(dir, 'scene', 'manifest.json'), '{"ok":1}');
  await writeFile(path.join(dir, 'secret.txt'), 'SECRET');
  await symlink(path.join(dir, 'secret.txt'), path.join(dir, 'root', 'link-out.txt'));
  await symlink(path.join(dir, 'scene'), path.join(dir, 'root', 'dir-link'));
  await symlink(path.join(dir, 'root', 'index.html'), path.join(dir, 'root', 'link-in.html'));
  server = createServer([['/', path.join(dir, 'root')], ['/scene/', path.join(dir, 'scene')]]);
  base = await listen(server, 0);
});

after(async () => {
  await new Promise((r) => server.close(r));
  await rm(dir, { recursive: true, force: true });
});

/** Raw request (no client-side normalisation of the path, unlike fetch). */
function get(rawPath, method = 'GET') {
  const u = new URL(base);
  return new Promise((resolve, reject) => {
    const req = http.request({ host: u.hostname, port: u.port, path: rawPath, method }, (res) => {
      let body = '';
      res.on('data', (c) => { body += c; });
      res.on('end', () => resolve({ status: res.statusCode, body }));
    });
    req.on('error', reject);
    req.end();
  });
}

test('binds to 127.0.0.1 only', () => {
  assert.equal(server.address().address, '127.0.0.1');
});

test('serves files inside the roots', async () => {
  assert.deepEqual(await get('/'), { status: 200, body: 'INDEX' });
  assert.deepEqual(await get('/index.html?x=1'), { status: 200, body: 'INDEX' });
  assert.deepEqual(await get('/sub/a%20b.txt'), { status: 200, body: 'SPACED' });
  assert.deepEqual(await get('/scene/manifest.json'), { status: 200, body: '{"ok":1}' });
  assert.deepEqual(await get('/link-in.html'), { status: 200, body: 'INDEX' }, 'a symlink inside the root is fine');
});

test('dot-dot in every spelling is refused', async () => {
  for (const p of ['/../secret.txt', '/sub/../../secret.txt', '/%2e%2e/secret.txt', '/%2E%2E/secret.txt', '/sub/%2e%2e/%2e%2e/secret.txt',
    '/..%2fsecret.txt', '/%2e%2e%2fsecret.txt', '/sub/..%5c..%5csecret.txt', '/scene/../../secret.txt', '/scene/%2e%2e/secret.txt', '/./index.html']) {
    const r = await get(p);
    assert.ok(r.status === 400 || r.status === 404 || r.status === 403, `${p}: ${r.status}`);
    assert.notEqual(r.body, 'SECRET', p);
  }
});

test('absolute paths, backslashes, NUL and bad escapes are refused', async () => {
  for (const p of [`/${path.join(dir, 'secret.txt')}`, `//${dir.slice(1)}/secret.txt`, `/%2F${encodeURIComponent(dir.slice(1))}%2Fsecret.txt`,
    '/%5c..%5csecret.txt', '/index.html%00.txt', '/%zz', 'secret.txt']) {
    const r = await get(p);
    assert.ok(r.status >= 400, `${p}: ${r.status}`);
    assert.notEqual(r.body, 'SECRET', p);
  }
});

test('symlinks that leave the root are refused', async () => {
  const r = await get('/link-out.txt');
  assert.equal(r.status, 403);
  assert.notEqual(r.body, 'SECRET');
  assert.equal((await get('/dir-link/manifest.json')).status, 403, 'a directory symlink out of the root');
});

test('only GET and HEAD', async () => {
  assert.equal((await get('/index.html', 'HEAD')).status, 200);
  assert.equal((await get('/index.html', 'POST')).status, 405);
  assert.equal((await get('/index.html', 'DELETE')).status, 405);
});

test('missing files are 404', async () => {
  assert.equal((await get('/nope.js')).status, 404);
  assert.equal((await get('/scene/nope.bin')).status, 404);
});
