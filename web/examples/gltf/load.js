// A model file into a three.js scene graph, by three.js's own loaders, chosen by the file's
// extension: .gltf / .glb (GLTFLoader), .obj (OBJLoader), .ply (PLYLoader); a trailing .gz is
// decompressed in the browser first (DecompressionStream), so the shared scenes
// (crytek-sponza.obj.gz, ...) load as they are stored. Errors name the file.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OBJLoader } from 'three/addons/loaders/OBJLoader.js';
import { PLYLoader } from 'three/addons/loaders/PLYLoader.js';

/** A model that could not be loaded; the message names the file. */
export class ModelError extends Error {}

/** The format of `url` by its extension (after any .gz): 'gltf', 'glb', 'obj' or 'ply'. */
export function formatOf(url) {
  const name = new URL(url, 'http://x/').pathname.toLowerCase().replace(/\.gz$/, '');
  const ext = name.slice(name.lastIndexOf('.') + 1);
  if (!['gltf', 'glb', 'obj', 'ply'].includes(ext)) throw new ModelError(`${url}: unknown model format ".${ext}" (expected .gltf, .glb, .obj or .ply, optionally .gz)`);
  return ext;
}

async function fetchBytes(url) {
  let response;
  try {
    response = await fetch(url);
  } catch (e) {
    throw new ModelError(`${url}: cannot be fetched (${e.message})`);
  }
  if (!response.ok) throw new ModelError(`${url}: HTTP ${response.status} ${response.statusText}`);
  if (!/\.gz$/i.test(new URL(url, location.href).pathname)) return response.arrayBuffer();
  try {
    return await new Response(response.body.pipeThrough(new DecompressionStream('gzip'))).arrayBuffer();
  } catch (e) {
    throw new ModelError(`${url}: not a readable gzip file (${e.message})`);
  }
}

/**
 * Loads `url` (relative to the page) and returns its root Object3D. OBJ and PLY get a plain
 * MeshStandardMaterial where the loader gives none (PLY); glTF keeps its own materials.
 */
export async function loadModel(url) {
  const format = formatOf(url);
  const absolute = new URL(url, location.href).href;
  const bytes = await fetchBytes(absolute);
  // Resources a .gltf names (buffers, textures) resolve against the file's own folder.
  const folder = absolute.slice(0, absolute.lastIndexOf('/') + 1);
  try {
    if (format === 'gltf' || format === 'glb') {
      const gltf = await new GLTFLoader().parseAsync(bytes, folder);
      // Its animations travel with the scene (three.js's convention: Object3D.animations).
      gltf.scene.animations = gltf.animations;
      return gltf.scene;
    }
    if (format === 'obj') return new OBJLoader().parse(new TextDecoder().decode(bytes));
    const geometry = new PLYLoader().parse(bytes);
    if (!geometry.attributes.position || geometry.attributes.position.count === 0) throw new Error('no vertices');
    const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({ color: 0xdddddd }));
    mesh.name = url;
    return mesh;
  } catch (e) {
    throw new ModelError(`${url}: ${format.toUpperCase()} could not be parsed (${e.message})`);
  }
}
