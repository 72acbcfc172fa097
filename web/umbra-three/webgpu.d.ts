// Types of umbra-three/webgpu: exact shadows in three.js's WebGPURenderer (README.md, "With
// WebGPURenderer"). An ES module with `three` (^0.187.0) as a peer dependency; it imports
// 'three/webgpu' and 'three/tsl'.
import type { Object3D, Camera, Light, Texture } from 'three';
import type { WebGPURenderer } from 'three/webgpu';
import type { UmbraError } from './index.js';

export type { UmbraError };

export interface UmbraWebGPUInfo {
  /** Always 'webgpu'. */
  backend: 'webgpu';
  /** The method deciding the lights (UmbraWebGPUOptions.method). */
  method: UmbraWebGPUMethod;
  /** 'compute' with 'cs-silhouette' (every frame's silhouettes from compute shaders, umbra-wgpu's WGSL); null with 'ray-bvh'. */
  silhouettes: 'compute' | null;
  /** With 'ray-bvh', the last BVH built (when the drawn geometry changed): its nodes, depth, build milliseconds (wasm, main thread) and GPU bytes; else null. */
  bvh: { nodes: number; depth: number; buildMs: number; bytes: number } | null;
  /** Shadow-casting lights umbra shadowed in the last frame (PointLight, SpotLight as a point light, DirectionalLight). */
  lights: number;
  /** Casters of the last frame: meshes with castShadow, each drawn instance of an InstancedMesh. */
  casters: number;
  /** Triangles of umbra's depth pass (every drawn mesh, world space, after welding for casters). */
  triangles: number;
  /** The casters' triangles. */
  casterTriangles: number;
  /** The casters' edge records (one side quad per unit of multiplicity when a silhouette). */
  records: number;
  /** Per light: whether it was counted z-pass in the last frame (the eye's count proven for its whole near pyramid; always false with 'ray-bvh', which counts nothing). */
  zpass: boolean[];
  /** UmbraWebGPUOptions.volumeCull as in force (false with 'ray-bvh'). */
  volumeCull: boolean;
  /** Per light: whether its volume was culled on the GPU in the last frame (false where volumeCull is off, or for a z-pass light whose receiver map cannot bound the eye's near pyramid: drawn whole). */
  culled: boolean[];
  /** Total milliseconds spent preparing topologies (wasm) so far. */
  prepareMs: number;
  /** Main-thread milliseconds umbra spent in the last render() before three.js's own frame. */
  cpuMs: number;
  /** Bytes of umbra's own GPU buffers and textures (geometry, per-light work buffers, depth-stencil target, masks). */
  gpuBytes: number;
  /** The depth-stencil format of umbra's depth pass ('depth32float-stencil8' where the device has it). */
  depthFormat: string;
}

/**
 * How the lights are decided, by native umbra's `--method` names: 'cs-silhouette' (shadow
 * volumes from compute-shader silhouettes, z-fail counting) or 'ray-bvh' (one shadow ray per
 * visible sample through a BVH of the casters, built in the wasm when the drawn geometry
 * changes). Both are exact; 'ray-bvh' costs more per pixel and nothing per caster edge.
 */
export type UmbraWebGPUMethod = 'cs-silhouette' | 'ray-bvh';

export interface UmbraWebGPUOptions {
  /** umbra_wasm.wasm: a URL, Response, bytes or compiled Module (default: beside this module). */
  wasm?: string | URL | Response | ArrayBuffer | ArrayBufferView | WebAssembly.Module;
  /** Default 'cs-silhouette'; any other value is refused by create() with the valid names. */
  method?: UmbraWebGPUMethod;
  /** false: every light counted z-fail. Default true: a light is counted z-pass (no caps, the eye's count as the start) where the casters' tests prove the eye's count for its whole near pyramid. */
  zpass?: boolean;
  /**
   * Default true: each light's volumes are culled on the GPU before they are drawn, every
   * caster piece (triangles joined across shared edges) that no visible sample lies behind is
   * dropped (native cs-silhouette's cull, umbra-wgpu's cull.wgsl; exact, no read-back). false:
   * every volume drawn whole. Ignored with 'ray-bvh'; anything but a boolean is refused.
   */
  volumeCull?: boolean;
}

/** What one light's volumes drew in the last frame (UmbraShadows.readVolumesAsync). */
export interface UmbraDrawnVolume {
  /** Whether the volume was culled (info.culled). */
  culled: boolean;
  /** Caster triangles kept by the cull (all of them when not culled). */
  triangles: number;
  /** Side quads drawn, one per unit of an edge's multiplicity. */
  edges: number;
}

/**
 * umbra's shadows for a WebGPURenderer. Call `render(scene, camera)` in place of
 * `renderer.render(scene, camera)`; each shadow-casting light gets `light.shadow.shadowNode`, a
 * node reading umbra's decision at the fragment's pixel, so every lit node material (and a
 * user's TSL) receives it. Needs `renderer.shadowMap.enabled = true`, and receivers with
 * `receiveShadow`. Create it before the lights' first frame: three.js keeps a light's shadow
 * node once its materials are built.
 */
export class UmbraShadows {
  /**
   * Awaits `renderer.init()` and loads the wasm. Rejects when the renderer runs on its WebGL 2
   * backend (no WebGPU adapter: use 'umbra-three' with a WebGLRenderer there) or its GPUDevice
   * lacks 'clip-distances' or 'depth-clip-control'.
   */
  static create(renderer: WebGPURenderer, options?: UmbraWebGPUOptions): Promise<UmbraShadows>;
  /** false: frames are drawn unshadowed (the masks cleared to lit). */
  enabled: boolean;
  /** Refused meshes, lights and frames, in order; never thrown from render(). */
  readonly errors: UmbraError[];
  /** Called once per new entry of `errors`. */
  onError: ((error: UmbraError) => void) | null;
  readonly info: UmbraWebGPUInfo;
  /** The depth-stencil format of umbra's depth pass. */
  readonly depthFormat: string;
  /** Draws umbra's passes, then `renderer.render(scene, camera)` (into the renderer's current render target). */
  render(scene: Object3D, camera: Camera): void;
  /** The light's decision of the last frame: rows top-down, 255 lit / 0 shadowed. */
  readMaskAsync(light: Light): Promise<Uint8Array>;
  /** Per light of the last frame (info.culled's order), what its volumes drew, read back from the GPU; [] with 'ray-bvh'. */
  readVolumesAsync(): Promise<UmbraDrawnVolume[]>;
  /** The light's mask texture (r8unorm, 1 lit / 0 shadowed, the frame's size), or null before its first frame. */
  maskTexture(light: Light): Texture | null;
  /** Frees umbra's GPU objects and removes the shadow nodes it set. */
  dispose(): void;
}

export { TopologyError } from './index.js';
