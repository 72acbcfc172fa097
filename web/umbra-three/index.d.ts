// Types of umbra-three (README.md has the use). The package is an ES module with `three`
// (^0.187.0) as a peer dependency.
import type { WebGLRenderer, Object3D, Camera, Light, Texture } from 'three';

/** A mesh or other object umbra refused, and why; the object still renders, without umbra's shadow. */
export interface UmbraError {
  /** The object's name, else its uuid ('(frame)' for a frame umbra could not draw). */
  mesh: string;
  message: string;
}

export interface UmbraInfo {
  /** Lights umbra shadowed in the last frame (at most 4). */
  lights: number;
  /** Casters (meshes with castShadow and a prepared topology; each drawn instance of an InstancedMesh or BatchedMesh) in the last frame. */
  casters: number;
  /** Alpha-tested casters of the last frame that cast through three.js's shadow map (`alphaCasters: 'shadowMap'`), by name (else uuid). */
  mapCasters: string[];
  /** Their triangles after welding. */
  triangles: number;
  /** Total milliseconds spent preparing topologies (wasm) so far. */
  prepareMs: number;
  /**
   * Main-thread milliseconds umbra spent in the last render() before three.js's own frame: its
   * passes' commands, the wasm's work and any read-back it waited for (with `volumeCull`, the
   * receiver maps; with `timing`, every pass).
   */
  cpuMs: number;
  /**
   * Bytes of umbra's own GPU buffers and textures after the last frame drawn: each caster's
   * topology and silhouette textures, each mesh's depth-pass buffers, the shared polygon
   * storage of the volume passes, and umbra's targets (mask, depth-stencil, the cull's).
   */
  gpuBytes: number;
  /** Whether the last frame reused the decisions of the one before (`cache`: nothing umbra draws from moved). */
  reused: boolean;
  /** Milliseconds per pass of the last frame (clearance, depth, volumes, mask), only with `timing = true`. */
  passes: Record<string, number>;
  /**
   * Per light of the last frame: its count's stencil start when it was counted z-pass (the
   * eye's near pyramid proven inside W0 volumes for every caster: sum(W0) mod 256), null when
   * it was counted z-fail.
   */
  zpass: (number | null)[];
  /** Whether volumes are culled to their receivers on this context (`volumeCull`, and EXT_color_buffer_float offered). */
  volumeCull: boolean;
  /** Why `volumeCull` is off (a missing extension, or 'auto' on a GPU), else null. */
  volumeCullMessage: string | null;
  /** Where the unculled silhouettes are computed (`silhouettes`, 'auto' resolved): 'wasm' or 'gpu'. */
  silhouettes: 'wasm' | 'gpu';
  /**
   * Main-thread milliseconds of the last frame drawn, by part: the scene walked and its meshes
   * placed, the z-pass tests, the passes issued (silhouettes, uploads and read-backs included).
   */
  cpu: { scene: number; clearance: number; passes: number };
  /** Where the receiver maps are scattered: 'gpu', 'cpu' (in the wasm), or null without the cull. */
  receiverScatter: 'gpu' | 'cpu' | null;
  /** Per light of the last frame: what its shadow volumes drew. */
  volumes: UmbraVolumes[];
  /**
   * An OrthographicCamera's frame: the view distances of the near plane (the camera's) and of
   * the far plane umbra's own passes used (beyond every volume's far ends and the drawn meshes'
   * box; `umbra verify --ortho-far` judges a mask with it); null for a PerspectiveCamera.
   */
  ortho: { near: number; far: number } | null;
}

/** What one light's shadow volumes drew in the last frame, summed over its casters. */
export interface UmbraVolumes {
  /** Whether they were culled to the light's receiver map (false: volumeCull off, or a z-pass light whose map cannot bound the eye's near pyramid). */
  culled: boolean;
  /** Triangles whose volumes were drawn: the kept ones when culled, else every caster triangle. */
  triangles: number;
  /** Edge records of nonzero multiplicity (the silhouette's sides) drawn; with `silhouettes: 'gpu'`, every record the sides' pass visited. */
  edges: number;
  /** Casters whose culled volume was also clamped (sides ending at far caps short of infinity, where that covers fewer pixels). */
  clamped: number;
  /** Casters whose unculled silhouette was kept from an earlier frame (`cache`: the light did not move in the caster's space). */
  cached: number;
}

export interface UmbraOptions {
  /** umbra_wasm.wasm: its URL, a Response, its bytes or a compiled module (default: beside the package's module). */
  wasm?: string | URL | Response | ArrayBuffer | ArrayBufferView | WebAssembly.Module;
  /** Diagnostic: 'standard' draws umbra's depth pass without reversed-Z even where EXT_clip_control is offered. */
  depth?: 'reversed' | 'standard';
  /** Diagnostic: false leaves EXT_depth_clamp off even where it is offered. */
  depthClamp?: boolean;
  /** Diagnostic: every vertex umbra draws on a 1/snap-pixel grid (0: off). */
  snap?: number;
  /** Diagnostic: false counts every light z-fail, never z-pass (the same decision, slower). */
  zpass?: boolean;
  /**
   * Shadow volumes only where something visible receives them: per light a map of the frame's
   * visible samples, against which each caster's volume is culled and clamped exactly. false:
   * every volume runs to infinity. 'auto' (the default): on where the renderer is a software
   * rasteriser (SwiftShader, llvmpipe), where fill is the frame's cost; off on a GPU, where
   * reading the maps back every frame would make the main thread wait for the GPU
   * (`info.volumeCullMessage` says so).
   */
  volumeCull?: boolean | 'auto';
  /**
   * Keep work that nothing changed (default true): a caster's unculled silhouette per light
   * while the light stays where it is in the caster's space, and the whole frame's decisions
   * while the camera, the lights and every drawn mesh's geometry and matrix stay the same.
   * false: everything computed again every frame (benchmarks of a moving view).
   */
  cache?: boolean;
  /**
   * Where the unculled silhouettes are computed: 'wasm' (every triangle oriented and the
   * silhouette's records listed on the main thread), 'gpu' (a transform-feedback pass orients
   * the triangles, and the sides' pass visits every edge record: no main-thread work when a
   * light or a caster moves) or 'auto' (the default: 'gpu' on a GPU, 'wasm' on a software
   * rasteriser, where the GPU's work is the CPU's too and the wasm's short list draws fewer
   * polygons). Volumes culled to their receivers are always the wasm's.
   */
  silhouettes?: 'auto' | 'wasm' | 'gpu';
  /**
   * Casters whose material discards fragments (alphaTest > 0, with or without an alphaMap, or
   * alphaHash): 'shadowMap' (the default) casts them through three.js's own shadow map for
   * that light, umbra the rest, and the lit materials multiply the two (every mesh receives
   * that map in umbra's frame, whatever its receiveShadow; the light's shadow camera and
   * mapSize are three.js's as the user set them); 'triangles' casts their whole triangles with
   * umbra's volumes.
   */
  alphaCasters?: 'shadowMap' | 'triangles';
  /** Diagnostic: where the receiver maps are scattered ('auto': in the wasm on software rasterisers, else on the GPU). */
  receiverScatter?: 'auto' | 'gpu' | 'cpu';
  /** Diagnostic: clamp culled volumes 'always', 'never', or where it covers fewer pixels ('auto'). */
  volumeClamp?: 'auto' | 'always' | 'never';
  /** Diagnostic: the samples' positions drawn by a pass of their own over the depth ('equal', default) or by the depth pass itself ('mrt'). */
  positionPass?: 'equal' | 'mrt';
}

export class UmbraShadows {
  /** Loads the wasm and sets up on the renderer's WebGL 2 context; throws a clear Error when it cannot. */
  static create(renderer: WebGLRenderer, options?: UmbraOptions): Promise<UmbraShadows>;
  /** false: render() is renderer.render() and patched materials see every light as lit. */
  enabled: boolean;
  /** true: info.passes gets per-pass times (each pass waited for: slower; for benchmarks). */
  timing: boolean;
  /** Meshes refused (no positions, NaN positions, index out of range) and other problems, each once. */
  readonly errors: UmbraError[];
  /** Called once per new entry of `errors`. */
  onError: ((err: UmbraError) => void) | null;
  readonly info: UmbraInfo;
  /** The WebGL renderer string and its SUBPIXEL_BITS (for `umbra verify --subpixel-bits`). */
  readonly rendererName: string;
  readonly subpixelBits: number;
  /** 'reversed-z' or 'standard': umbra's depth convention on this context. */
  readonly depth: 'reversed-z' | 'standard';
  /** In place of renderer.render(scene, camera); never throws from umbra's part of the frame. */
  render(scene: Object3D, camera: Camera): void;
  /** The screen-sized texture holding the light's decision of the last frame (channel maskChannel(light)), or null. */
  maskTexture(light: Light): Texture | null;
  /** The RGBA channel of maskTexture(light) with the light's decision (1 lit, 0 shadowed), or -1. */
  maskChannel(light: Light): number;
  /** The light's decision of the last frame: width * height bytes, rows top-down, 255 lit / 0 shadowed (0 where no surface is seen); or null. */
  readMask(light: Light): Uint8Array | null;
  /** Frees umbra's GL objects; render() is then renderer.render() and patched materials see every light as lit. */
  dispose(): void;
}

/** The error umbra's topology step reports for a geometry it refuses (the message names the mesh). */
export class TopologyError extends Error {}
