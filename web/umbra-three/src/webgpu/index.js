// umbra-three/webgpu: exact shadows for three.js's WebGPURenderer (three/webgpu). The same
// preprocessing as the WebGL 2 path (../topology.js, WebAssembly); drawing by umbra-wgpu's
// WGSL compute silhouettes (passes.js); the decision reaches three.js's node materials as each
// light's shadow node. README.md shows the use; index.d.ts the types.
export { UmbraShadows } from './umbra-shadows-webgpu.js';
export { TopologyError } from '../topology.js';
