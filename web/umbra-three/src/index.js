// umbra-three: exact shadow volumes (umbra's paper 003 method) for three.js's WebGLRenderer.
// Preprocessing (topology.js, WebAssembly) and drawing (webgl/) are apart, so that another
// drawer (WebGPU) can be added beside webgl/. README.md shows the use; index.d.ts the types.
export { UmbraShadows } from './umbra-shadows.js';
export { TopologyError } from './topology.js';
