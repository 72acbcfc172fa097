// Which of three.js's light uniforms a light lands in, so that a patched material multiplies
// the right light by umbra's decision. WebGLRenderer gathers the lights of the scene graph in
// traversal order (projectObject: an invisible object hides its subtree; a light counts when
// its layers meet the camera's), then WebGLLights.setup sorts them, stably, shadow casters
// first and lights with a map next (shadowCastingAndTexturingLightsFirst), and numbers each
// kind apart: the i-th PointLight of that order is pointLights[i], the i-th
// DirectionalLight directionalLights[i]. This file replays that order; test/lights.test.mjs
// checks it against three.js's own WebGLLights. No three.js import: plain objects.

/** three.js's comparator (src/renderers/webgl/WebGLLights.js, r187). */
export function shadowCastingAndTexturingLightsFirst(a, b) {
  return (b.castShadow ? 2 : 0) - (a.castShadow ? 2 : 0) + (b.map ? 1 : 0) - (a.map ? 1 : 0);
}

/** The lights three.js would gather from `scene` for `camera`, in its traversal order. */
export function gatherLights(scene, camera) {
  const out = [];
  const visit = (o) => {
    if (o.visible === false) return;
    if (o.isLight && o.layers.test(camera.layers)) out.push(o);
    for (const c of o.children) visit(c);
  };
  visit(scene);
  return out;
}

/**
 * The uniform slot of every gathered light: Map light -> { kind: 'point' | 'directional' |
 * 'other', index } in the sorted order WebGLLights uses.
 */
export function lightSlots(lights) {
  const sorted = [...lights].sort(shadowCastingAndTexturingLightsFirst); // stable (ES2019)
  const slots = new Map();
  let point = 0;
  let directional = 0;
  for (const l of sorted) {
    // three.js tests isSunLight before isDirectionalLight: a sun is no directional light here.
    if (l.isSunLight) slots.set(l, { kind: 'other', index: -1 });
    else if (l.isPointLight) slots.set(l, { kind: 'point', index: point++ });
    else if (l.isDirectionalLight) slots.set(l, { kind: 'directional', index: directional++ });
    else slots.set(l, { kind: 'other', index: -1 });
  }
  return slots;
}
