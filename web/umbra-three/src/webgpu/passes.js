// The WebGPU drawer of umbra-three: native cs-silhouette (paper 001, compute-shader
// silhouettes; crates/umbra-wgpu/src/methods/cs_silhouette.rs) on three.js's own GPUDevice,
// from umbra-wgpu's WGSL files themselves (the virtual module `umbra:wgsl`, read from
// crates/umbra-wgpu/src/shaders/ by build.mjs: a shader fixed natively is fixed here).
//
// Per frame, in one command encoder submitted before three.js draws:
//   1. depth pass: every drawn triangle (world space, world.js) into umbra's own
//      depth-stencil target (wgsl/surface.wgsl vs_surface: clip_from_world * (p, 1),
//      invariant, the expression of the native vertex stages), reversed-Z with an infinite
//      far plane;
//   2. per light: the command words reset, then three compute passes over the casters
//      (transform.wgsl: every vertex to clip space, as itself and extruded; orientation.wgsl
//      orient_and_caps: every triangle's orientation once, its caps compacted; cs_sides.wgsl:
//      every edge record's multiplicity, its quads compacted) and umbra-three's own classify
//      pass (wgsl/classify.wgsl: each side, light cap and dark cap inside the viewport, outside
//      it, or crossing its border), then one render pass: the stencil cleared to 0, the
//      polygons drawn with two indirect draws under z-fail counting (wgsl/fan.wgsl: the inside
//      ones as they are, the crossing ones clipped in the vertex stage to just inside the
//      viewport and the near plane, so that SwiftShader's clipper never cracks a volume;
//      wgsl/polygon.wgsl says why), and the decision written into the light's mask (mask.wgsl:
//      white where the count is 0, lit; the mask was cleared to black, shadowed), then the
//      seen side's facing on the depth pass's surface where the count is 0 (surface.wgsl
//      fs_facing: lit = count 0 AND the seen side faces the light, native umbra's decision).
// A light given a cull uniform (UmbraShadows' `volumeCull`) has its volume culled on the GPU
// first, as native cs-silhouette's is (umbra-wgpu's methods/gpu_cull.rs, cull.wgsl; the proof:
// docs/exactness.md, "Volumes culled on the GPU"): once per frame a samples pass keeps each
// pixel's visible sample (wgsl/samples.wgsl), then per light its samples are scattered into
// the light's receiver map (wgsl/scatter.wgsl), cull.wgsl raises the eye's near pyramid under
// z-pass, builds the map's max pyramid and marks the caster pieces a visible sample may lie
// behind, and the orientation pass (orient_kept entries) gives the other pieces' triangles
// orientation 0: no side, no cap. No read-back.
// With `rays` set (UmbraShadows' method 'ray-bvh', rays.js), step 2 is instead a pass that keeps
// each pixel's visible sample, then per light one pass that walks each sample's shadow ray.
// A light counts z-pass where zpass.js proved the eye's count W0 for the eye's whole near
// pyramid (the stencil cleared to W0, the sides alone counted in front of the sample, no caps);
// every other light counts z-fail (exact wherever the eye is: closed volumes, caps at infinity,
// light caps pushed to the far plane and clipped at the near plane). Buffers that only one light's
// passes use at a time (clip positions, orientations, caps, quads, commands) are shared by the
// lights: the queue runs one light's passes after the other's.
import WGSL from 'umbra:wgsl';
import MASK from './wgsl/mask.wgsl';
import SURFACE from './wgsl/surface.wgsl';
import POLYGON from './wgsl/polygon.wgsl';
import CLASSIFY from './wgsl/classify.wgsl';
import FAN from './wgsl/fan.wgsl';
import SAMPLE_BITS from './wgsl/sample_bits.wgsl';
import SAMPLES from './wgsl/samples.wgsl';
import SCATTER from './wgsl/scatter.wgsl';
import { casterPieces, triangleNormals } from './world.js';

/** Bytes of one light's uniform slot (UmbraLight in volume.wgsl, padded to 256: the largest uniform offset alignment WebGPU allows). */
export const LIGHT_SLOT_BYTES = 256;
/** Bytes of UmbraLight as volume.wgsl declares it. */
const LIGHT_BYTES = 224;
/** Invocations per workgroup of every compute entry point (@workgroup_size(256)). */
const GROUP = 256;
/** Most workgroups along one dispatch dimension (WebGPU's maxComputeWorkgroupsPerDimension default). */
const MAX_GROUPS = 65535;

const ENABLE = 'enable clip_distances;\n';

/** Cells along a side of the page's receiver maps (the WebGL path's side, PAGE_RECEIVER_SIDE). */
export const CULL_SIDE = 128;
/** u32 words of the cull's uniform (umbra_geom::receivers::GPU_CULL_WORDS, the wasm's gpuCull). */
const CULL_WORDS = 52;
/** The samples texture's "no sample" word (sample_bits.wgsl NO_SAMPLE). */
const NO_SAMPLE = 0xffffffff;

/** Device features the drawer needs, with why. */
export const REQUIRED_FEATURES = {
  // The volumes' clip distances: the near-plane cut of light caps (volume.wgsl).
  'clip-distances': 'the near-plane clip of light caps (volume.wgsl clip_distances)',
  // Nothing of a volume may be clipped at the far plane: vertices at infinity land on it.
  'depth-clip-control': 'unclipped depth for the volumes (their vertices at infinity lie on the far plane)',
};

/** The [x, y] workgroups that cover `n` invocations (volume.wgsl umbra_item's 2D grid). */
export function dispatchSize(n) {
  const groups = Math.max(1, Math.ceil(n / GROUP));
  const x = Math.min(groups, MAX_GROUPS);
  return [x, Math.ceil(groups / x)];
}

const U = GPUBufferUsage;

export class WebGPUVolumes {
  /**
   * `device`: three.js's GPUDevice (renderer.backend.device); `depthFormat`: the
   * depth-stencil format of umbra's target (depth32float-stencil8 where the device has it).
   * Throws, naming the feature, when the device lacks one the passes need.
   */
  constructor(device, depthFormat) {
    for (const [f, why] of Object.entries(REQUIRED_FEATURES)) {
      if (!device.features.has(f)) throw new Error(`the GPUDevice has no '${f}' feature (needed for ${why})`);
    }
    this.device = device;
    this.depthFormat = depthFormat;
    this.maskFormat = 'r8unorm';
    const module = (label, parts) => device.createShaderModule({ label: `umbra ${label}`, code: ENABLE + parts.join('\n') });
    const transform = module('transform', [WGSL.volume, WGSL.transform]);
    const orient = module('orientation', [WGSL.volume, WGSL.multiplicity, WGSL.orientation]);
    const sides = module('sides', [WGSL.volume, WGSL.csSides]);
    const classify = module('classify', [WGSL.volume, POLYGON, CLASSIFY]);
    const fan = module('fan', [WGSL.volume, POLYGON, FAN]);
    // The depth and the facing pass: one vertex stage (vs_surface), the same positions and depths.
    const surface = module('surface', [WGSL.volume, SURFACE]);
    const mask = device.createShaderModule({ label: 'umbra mask', code: MASK });

    const C = GPUShaderStage.COMPUTE;
    const V = GPUShaderStage.VERTEX;
    const F = GPUShaderStage.FRAGMENT;
    this.lightLayout = device.createBindGroupLayout({
      label: 'umbra light slot',
      entries: [{ binding: 0, visibility: C | V | F, buffer: { type: 'uniform', hasDynamicOffset: true, minBindingSize: LIGHT_BYTES } }],
    });
    // Group 1 of each stage: its storage buffers, read-only or written (the WGSL's declarations).
    const group = (label, visibility, kinds) => device.createBindGroupLayout({
      label: `umbra ${label}`,
      entries: kinds.map((k, i) => ({ binding: i, visibility, buffer: { type: k === 'w' ? 'storage' : 'read-only-storage' } })),
    });
    this.transformLayout = group('transform', C, ['r', 'w']);
    this.orientLayout = group('orientation', C, ['r', 'r', 'w', 'w', 'w']);
    this.sidesLayout = group('sides', C, ['r', 'r', 'r', 'w', 'w']);
    this.classifyLayout = group('classify', C, ['r', 'r', 'r', 'r', 'r', 'w', 'w']);
    this.classifyUniformLayout = device.createBindGroupLayout({ label: 'umbra classify uniform', entries: [{ binding: 0, visibility: C, buffer: { type: 'uniform' } }] });
    this.fanLayout = group('fan', V, ['r', 'r', 'r', 'r']);
    this.surfaceLayout = group('surface', V | F, ['r', 'r', 'r']);
    const layout = (g1, g2) => device.createPipelineLayout({ bindGroupLayouts: [this.lightLayout, g1, g2].filter(Boolean) });
    const compute = (m, entryPoint, g1, g2) => device.createComputePipeline({ label: `umbra ${entryPoint}`, layout: layout(g1, g2), compute: { module: m, entryPoint } });
    this.transformPipeline = compute(transform, 'transform', this.transformLayout);
    this.orientPipeline = compute(orient, 'orient_and_caps', this.orientLayout);
    // z-pass lights: the orientations alone (no caps: z-pass counts the sides only).
    this.orientOnlyPipeline = compute(orient, 'orient', this.orientLayout);
    this.sidesPipeline = compute(sides, 'sides', this.sidesLayout);
    this.classifyPipeline = compute(classify, 'classify_polygons', this.classifyLayout, this.classifyUniformLayout);

    // The GPU cull (cull.wgsl, scatter.wgsl): group 1 the light's grid (a 256-byte slot per
    // light) and the buffers, group 2 one pyramid level, group 3 the samples.
    const cull = module('cull', [WGSL.volume, WGSL.receiverCell, WGSL.cull, SAMPLE_BITS, SCATTER]);
    this.cullLayout = device.createBindGroupLayout({
      label: 'umbra cull',
      entries: [
        { binding: 0, visibility: C, buffer: { type: 'uniform', hasDynamicOffset: true, minBindingSize: 4 * CULL_WORDS } },
        { binding: 1, visibility: C, buffer: { type: 'storage' } },
        { binding: 2, visibility: C, buffer: { type: 'read-only-storage' } },
        { binding: 3, visibility: C, buffer: { type: 'read-only-storage' } },
        { binding: 4, visibility: C, buffer: { type: 'read-only-storage' } },
        { binding: 5, visibility: C, buffer: { type: 'storage' } },
      ],
    });
    this.levelLayout = device.createBindGroupLayout({ label: 'umbra cull level', entries: [{ binding: 0, visibility: C, buffer: { type: 'uniform', hasDynamicOffset: true, minBindingSize: 16 } }] });
    this.scatterLayout = device.createBindGroupLayout({
      label: 'umbra scatter',
      entries: [
        { binding: 0, visibility: C, texture: { sampleType: 'uint' } },
        { binding: 1, visibility: C, buffer: { type: 'read-only-storage' } },
      ],
    });
    const cullLayout = device.createPipelineLayout({ bindGroupLayouts: [this.lightLayout, this.cullLayout, this.levelLayout] });
    const scatterLayout = device.createPipelineLayout({ bindGroupLayouts: [this.lightLayout, this.cullLayout, this.levelLayout, this.scatterLayout] });
    const cullPipeline = (entryPoint, l) => device.createComputePipeline({ label: `umbra ${entryPoint}`, layout: l, compute: { module: cull, entryPoint } });
    this.scatterPipeline = cullPipeline('scatter_samples', scatterLayout);
    this.raisePipeline = cullPipeline('raise', cullLayout);
    this.reducePipeline = cullPipeline('reduce', cullLayout);
    this.needPipeline = cullPipeline('need', cullLayout);
    // The orientation after the cull: the pieces and their flags too (orientation.wgsl).
    this.orientKeptLayout = group('orientation after the cull', C, ['r', 'r', 'w', 'w', 'w', 'r', 'w']);
    this.orientKeptPipeline = compute(orient, 'orient_kept_and_caps', this.orientKeptLayout);
    this.orientKeptOnlyPipeline = compute(orient, 'orient_kept', this.orientKeptLayout);
    // The pyramid (six faces of CULL_SIDE cells, then each coarser level) and one level slot
    // per level built: { finer level's offset, this level's offset, its side }.
    this.cullOffsets = [0];
    for (let side = CULL_SIDE; side >= 1; side /= 2) this.cullOffsets.push(this.cullOffsets.at(-1) + 6 * side * side);
    this.cullLevels = this.cullOffsets.length - 1;
    const levelSlots = new Uint32Array((LIGHT_SLOT_BYTES / 4) * (this.cullLevels - 1));
    for (let k = 1; k < this.cullLevels; k++) levelSlots.set([this.cullOffsets[k - 1], this.cullOffsets[k], CULL_SIDE >> k, 0], (LIGHT_SLOT_BYTES / 4) * (k - 1));
    this.cullLevelBuffer = this.buffer('umbra cull levels', levelSlots.byteLength, U.UNIFORM, levelSlots);
    this.cullLevelGroup = device.createBindGroup({ layout: this.levelLayout, entries: [{ binding: 0, resource: { buffer: this.cullLevelBuffer, size: 16 } }] });
    this.cells = this.buffer('umbra receiver pyramid', 4 * this.cullOffsets[this.cullLevels], U.STORAGE | U.COPY_DST);
    this.cullUniforms = null;
    // The samples pass (samples.wgsl): the depth pass's surface, each pixel's visible sample.
    const samples = module('samples', [WGSL.volume, SURFACE, SAMPLE_BITS, SAMPLES]);
    this.samplesPipeline = device.createRenderPipeline({
      label: 'umbra samples',
      layout: layout(this.surfaceLayout),
      vertex: { module: samples, entryPoint: 'vs_surface' },
      fragment: { module: samples, entryPoint: 'fs_sample', targets: [{ format: 'rgba32uint' }] },
      // Reason: the depth pass's primitive state (the same coverage and depths; both faces).
      primitive: { topology: 'triangle-list', cullMode: 'none', frontFace: 'ccw' },
      depthStencil: {
        format: depthFormat,
        // Reason: the depth pass's surface is kept for the lights.
        depthWriteEnabled: false,
        // Reason: exactly the depth pass's visible surface (the same vertex stage and state),
        // so what a pixel keeps is its visible sample.
        depthCompare: 'equal',
        // Reason: no count; the stencil is neither read nor written.
        stencilReadMask: 0,
        stencilWriteMask: 0,
      },
    });
    this.samplesTexture = null;
    // Per light of the last frame: [triangles the cull kept, side vertices] (readVolumes).
    this.drawnCounts = null;
    this.drawn = [];

    // The depth pass: depth only. Reason for vs_surface (vertices pulled from storage, a
    // non-indexed draw) rather than resolve.wgsl's vs_resolve: the facing pass needs each
    // fragment's triangle, and must see bit for bit this pass's depths (depth EQUAL), so both
    // run one vertex stage.
    this.depthPipeline = device.createRenderPipeline({
      label: 'umbra depth',
      layout: layout(this.surfaceLayout),
      vertex: { module: surface, entryPoint: 'vs_surface' },
      // Reason: both faces are surfaces a pixel can show (triangle soups are two-sided; the
      // oracle judges the nearest triangle, `umbra verify --receivers both`).
      primitive: { topology: 'triangle-list', cullMode: 'none' },
      depthStencil: {
        format: depthFormat,
        depthWriteEnabled: true,
        // Reason: reversed-Z, nearer is greater (cleared to 0, the far plane).
        depthCompare: 'greater',
      },
    });

    // The counting pipelines (the twin of umbra-wgpu's Common::counting_pipeline).
    const counting = (depthFailOp, passOp) => ({ compare: 'always', failOp: 'keep', depthFailOp, passOp });
    const volume = (entryPoint, zpass) => device.createRenderPipeline({
      label: `umbra ${entryPoint}`,
      layout: layout(this.fanLayout),
      vertex: { module: fan, entryPoint },
      // Reason: the volume pass only counts; the mask attachment is written by the mask pass
      // alone. The fragment stage keeps each fragment's depth within its triangle's corners.
      fragment: { module: fan, entryPoint: 'fs_fan', targets: [{ format: this.maskFormat, writeMask: 0 }] },
      primitive: {
        topology: 'triangle-list',
        // Reason: volume triangles are counter-clockwise seen from outside the volume.
        frontFace: 'ccw',
        // Reason: both faces are counted with different ops in one pass (two-sided stencil).
        cullMode: 'none',
        // Reason: nothing of a volume may be clipped by the far or the near plane (the fan's
        // vertices lie inside the viewport's x and y planes, but a side may reach in front of
        // the near plane, and light caps lie on the far plane); depth is clamped instead.
        unclippedDepth: true,
      },
      depthStencil: {
        format: depthFormat,
        // Reason: the volumes are invisible; the depth of the scene stays for the next light.
        depthWriteEnabled: false,
        // Reason: strictly nearer (reversed-Z GREATER): a light cap pushed to the far plane
        // (depth 0) fails at every sample, background included, and z-fail counts it everywhere.
        depthCompare: 'greater',
        // z-fail: faces behind the sample; a back face +1 (the ray leaves a volume after the
        // sample), a front face -1. z-pass (a light whose eye's count zpassStart proved): faces
        // in front of the sample; a front face +1 (the ray enters a volume before the sample),
        // a back face -1, from the eye's count. Wrapping: the count is exact modulo 256.
        stencilFront: zpass ? counting('keep', 'increment-wrap') : counting('decrement-wrap', 'keep'),
        stencilBack: zpass ? counting('keep', 'decrement-wrap') : counting('increment-wrap', 'keep'),
        stencilReadMask: 0xff,
        stencilWriteMask: 0xff,
        // Reason: an offset would move volume faces against the scene's depth.
        depthBias: 0,
      },
    });
    // [z-fail, z-pass] each.
    this.insideDraw = [volume('vs_inside', false), volume('vs_inside', true)];
    this.crossingDraw = [volume('vs_crossing', false), volume('vs_crossing', true)];

    // The decision: one triangle over the viewport, white where the count is the start (0).
    this.maskPipeline = device.createRenderPipeline({
      label: 'umbra mask',
      layout: device.createPipelineLayout({ bindGroupLayouts: [] }),
      vertex: { module: mask, entryPoint: 'vs_mask' },
      fragment: { module: mask, entryPoint: 'fs_mask', targets: [{ format: this.maskFormat }] },
      primitive: { topology: 'triangle-list', cullMode: 'none' },
      depthStencil: {
        format: depthFormat,
        depthWriteEnabled: false,
        // Reason: every pixel is decided, background included (lit: no volume counts there).
        depthCompare: 'always',
        stencilFront: { compare: 'equal', failOp: 'keep', depthFailOp: 'keep', passOp: 'keep' },
        stencilBack: { compare: 'equal', failOp: 'keep', depthFailOp: 'keep', passOp: 'keep' },
        stencilReadMask: 0xff,
        // Reason: the count is read, not changed.
        stencilWriteMask: 0,
      },
    });

    // The facing pass: after the mask pass, every drawn triangle again on the depth pass's
    // surface, where the count is 0, writing 1 where the seen side faces the light and 0 where
    // it faces away (surface.wgsl fs_facing says why). Of coplanar triangles at one depth the
    // last drawn decides, as in the WebGL path's mask pass.
    const equalZero = { compare: 'equal', failOp: 'keep', depthFailOp: 'keep', passOp: 'keep' };
    this.facingPipeline = device.createRenderPipeline({
      label: 'umbra facing',
      layout: layout(this.surfaceLayout),
      vertex: { module: surface, entryPoint: 'vs_surface' },
      fragment: { module: surface, entryPoint: 'fs_facing', targets: [{ format: this.maskFormat }] },
      // Reason: the depth pass's primitive state (the same coverage and depths; both faces).
      primitive: { topology: 'triangle-list', cullMode: 'none', frontFace: 'ccw' },
      depthStencil: {
        format: depthFormat,
        depthWriteEnabled: false,
        // Reason: exactly the depth pass's visible surface (the same vertex stage and state).
        depthCompare: 'equal',
        // Reason: only where the count is 0; elsewhere the mask stays shadowed.
        stencilFront: equalZero,
        stencilBack: equalZero,
        stencilReadMask: 0xff,
        stencilWriteMask: 0,
      },
    });

    // {0 vertices, 1 instance, 0, 0}: what each indirect command is reset to before its compute pass.
    this.commandTemplate = this.buffer('umbra command template', 16, U.COPY_SRC, new Uint32Array([0, 1, 0, 0]));
    this.sidesCommand = this.buffer('umbra sides command', 16, U.STORAGE | U.INDIRECT | U.COPY_DST | U.COPY_SRC);
    this.capsCommand = this.buffer('umbra caps command', 16, U.STORAGE | U.INDIRECT | U.COPY_DST);
    // The classify pass's two draws: [0] inside polygons, [1] crossing ones.
    this.fanCommands = this.buffer('umbra fan commands', 32, U.STORAGE | U.INDIRECT | U.COPY_DST);
    this.uniforms = null;
    this.lightSlots = 0;
    this.scene = null;
    this.target = null;
    /** The ray-bvh drawer (rays.js) when the lights are decided by shadow rays, else null. */
    this.rays = null;
  }

  /** A buffer of at least 16 bytes (WebGPU binds no empty buffer), filled with `data` if given. */
  buffer(label, bytes, usage, data = null) {
    const size = Math.max(16, Math.ceil(bytes / 4) * 4);
    const b = this.device.createBuffer({ label, size, usage, mappedAtCreation: !!data });
    if (data) {
      new Uint8Array(b.getMappedRange()).set(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
      b.unmap();
    }
    return b;
  }

  /** Bytes of umbra's own GPU buffers and textures now. */
  get gpuBytes() {
    let n = 16 + 32 + 32;
    if (this.scene) n += this.scene.bytes;
    if (this.uniforms) n += this.uniforms.size;
    if (this.target) n += this.target.bytes;
    if (this.rays) n += this.rays.gpuBytes;
    if (this.cullUniforms) n += this.cells.size + this.cullLevelBuffer.size + this.cullUniforms.size;
    if (this.samplesTexture) n += this.samplesTexture.bytes;
    return n;
  }

  /**
   * Uploads the frame's merged geometry (world.js mergeParts) and makes the buffers sized to it:
   * the surface's (positions, indices, normals) always, the volumes' only when the lights are
   * decided by volumes (not with `rays`, which reads the surface's alone).
   */
  setScene(merged) {
    this.disposeScene();
    const S = U.STORAGE;
    const s = {
      positions: this.buffer('umbra positions', 4 * merged.positions.length, S, merged.positions),
      indices: this.buffer('umbra indices', 4 * merged.indices.length, S, merged.indices),
      // The facing pass's flat normals (world.js triangleNormals), over every drawn triangle.
      normals: this.buffer('umbra normals', 4 * 4 * merged.triangles, S, triangleNormals(merged.positions, merged.indices)),
      indexCount: merged.indices.length,
      vertices: merged.casterVertices,
      triangles: merged.casterTriangles,
      recordCount: merged.records.length / 4,
      owned: ['positions', 'indices', 'normals'],
    };
    const bind = (layout, buffers) => this.device.createBindGroup({ layout, entries: buffers.map((buffer, binding) => ({ binding, resource: { buffer } })) });
    s.surfaceGroup = bind(this.surfaceLayout, [s.positions, s.indices, s.normals]);
    if (!this.rays) {
      Object.assign(s, {
        records: this.buffer('umbra edge records', 4 * merged.records.length, S, merged.records),
        slots: this.buffer('umbra slots', 4 * merged.slots.length, S, merged.slots),
        clip: this.buffer('umbra clip positions', 32 * merged.casterVertices, S),
        orientation: this.buffer('umbra orientations', 4 * merged.casterTriangles, S),
        caps: this.buffer('umbra caps', 12 * merged.casterTriangles, S),
        // Σ|m| <= Σk: at most one quad per slot.
        quads: this.buffer('umbra quads', 8 * merged.slots.length, S),
        // The classify pass's lists: at most every side quad, light cap and dark cap, each; the
        // crossing list starts at a 256-byte boundary (a storage binding's offset alignment).
        polygons: merged.slots.length + 2 * merged.casterTriangles,
      });
      s.crossingFirst = Math.max(64, Math.ceil(s.polygons / 64) * 64);
      s.lists = this.buffer('umbra polygon lists', 4 * 2 * s.crossingFirst, S);
      s.classifyUniform = this.buffer('umbra classify uniform', 16, U.UNIFORM, new Uint32Array([s.crossingFirst, 0, 0, 0]));
      // The GPU cull's pieces (per caster triangle) and flags (word 0 the triangles kept, 1 + p
      // piece p needed).
      const { pieces, count } = casterPieces(merged.records, merged.slots, merged.casterTriangles);
      s.pieces = this.buffer('umbra cull pieces', 4 * pieces.length, S, pieces);
      s.needed = this.buffer('umbra cull needed', 4 * (1 + count), S | U.COPY_DST | U.COPY_SRC);
      s.pieceCount = count;
      s.bounds = merged.bounds;
      s.owned.push('records', 'slots', 'clip', 'orientation', 'caps', 'quads', 'lists', 'classifyUniform', 'pieces', 'needed');
      s.transformGroup = bind(this.transformLayout, [s.positions, s.clip]);
      s.orientGroup = bind(this.orientLayout, [s.positions, s.indices, s.orientation, this.capsCommand, s.caps]);
      s.orientKeptGroup = bind(this.orientKeptLayout, [s.positions, s.indices, s.orientation, this.capsCommand, s.caps, s.pieces, s.needed]);
      s.sidesGroup = bind(this.sidesLayout, [s.records, s.slots, s.orientation, this.sidesCommand, s.quads]);
      s.classifyGroup = bind(this.classifyLayout, [s.clip, s.quads, s.caps, this.sidesCommand, this.capsCommand, this.fanCommands, s.lists]);
      s.classifyUniformGroup = bind(this.classifyUniformLayout, [s.classifyUniform]);
      const fanGroup = (offset) => this.device.createBindGroup({
        layout: this.fanLayout,
        entries: [s.clip, s.quads, s.caps].map((buffer, binding) => ({ binding, resource: { buffer } }))
          .concat([{ binding: 3, resource: { buffer: s.lists, offset: 4 * offset, size: 4 * s.crossingFirst } }]),
      });
      s.insideGroup = fanGroup(0);
      s.crossingGroup = fanGroup(s.crossingFirst);
    }
    s.bytes = s.owned.reduce((a, k) => a + s[k].size, 0);
    this.scene = s;
  }

  disposeScene() {
    if (!this.scene) return;
    for (const k of this.scene.owned) this.scene[k].destroy();
    this.scene = null;
  }

  /** umbra's depth-stencil target at `width` x `height` (made again when the size changes). */
  setSize(width, height) {
    if (this.target && this.target.width === width && this.target.height === height) return;
    if (this.target) this.target.texture.destroy();
    if (this.samplesTexture) this.samplesTexture.texture.destroy();
    this.samplesTexture = null;
    const texture = this.device.createTexture({ label: 'umbra depth-stencil', size: [width, height], format: this.depthFormat, usage: GPUTextureUsage.RENDER_ATTACHMENT });
    this.target = { width, height, texture, view: texture.createView(), bytes: width * height * (this.depthFormat === 'depth32float-stencil8' ? 5 : 4) };
  }

  /** Room for `n` light slots in the uniform buffer. */
  ensureLights(n) {
    if (this.uniforms && this.lightSlots >= n) return;
    if (this.uniforms) this.uniforms.destroy();
    this.lightSlots = Math.max(4, n);
    this.uniforms = this.buffer('umbra light slots', LIGHT_SLOT_BYTES * this.lightSlots, U.UNIFORM | U.COPY_DST);
    this.lightGroup = this.device.createBindGroup({ layout: this.lightLayout, entries: [{ binding: 0, resource: { buffer: this.uniforms, size: LIGHT_BYTES } }] });
  }

  /**
   * Draws the frame: `clipFromWorld` (Float32Array(16), column-major, reversed-Z, infinite far
   * plane), `lights` ([x, y, z, w] world space: w 1 point, 0 directional from xyz), their
   * masks (GPUTexture views, r8unorm, the target's size) and `zpass`: per light the eye's
   * count W0 when z-pass is proven for it (zpass.js zpassStart), null (or absent) for z-fail;
   * `cull`: per light the GPU cull's uniform (the wasm's receivers gpuCull: 52 u32, the near
   * pyramid raised under z-pass) to cull its volume with, null (or absent) to draw it whole.
   */
  draw(clipFromWorld, lights, masks, zpass = [], cull = []) {
    const s = this.scene;
    this.ensureLights(lights.length);
    const slots = new ArrayBuffer(LIGHT_SLOT_BYTES * Math.max(1, lights.length));
    lights.forEach((light, k) => {
      const f = new Float32Array(slots, k * LIGHT_SLOT_BYTES, LIGHT_BYTES / 4);
      const u = new Uint32Array(slots, k * LIGHT_SLOT_BYTES, LIGHT_BYTES / 4);
      f.set(clipFromWorld, 0);
      f.set(light, 16);
      // scene_planes (20..43) unused: z-fail, scene_clip 0; far_clip_z 0 (reversed-Z).
      f[44] = 0;
      u[45] = 0;
      // A directional light's dark cap has zero area (all its points at infinity coincide).
      u[46] = light[3] === 0 ? 3 : 6;
      u[47] = s ? s.triangles : 0;
      u[48] = s ? s.recordCount : 0;
      u[49] = 0;
      u[50] = s ? s.vertices : 0;
    });
    this.device.queue.writeBuffer(this.uniforms, 0, slots);
    const t = this.target;
    const encoder = this.device.createCommandEncoder({ label: 'umbra frame' });
    const depth = encoder.beginRenderPass({
      label: 'umbra depth',
      colorAttachments: [],
      depthStencilAttachment: { view: t.view, depthClearValue: 0, depthLoadOp: 'clear', depthStoreOp: 'store', stencilClearValue: 0, stencilLoadOp: 'clear', stencilStoreOp: 'store' },
    });
    if (s && s.indexCount > 0) {
      depth.setPipeline(this.depthPipeline);
      // Slot 0: every slot holds the same clip_from_world.
      depth.setBindGroup(0, this.lightGroup, [0]);
      depth.setBindGroup(1, s.surfaceGroup);
      depth.draw(s.indexCount);
    }
    depth.end();
    const casting = s && s.triangles > 0;
    const culled = lights.map((_, k) => !!(casting && !this.rays && cull[k]));
    if (!this.drawnCounts || this.drawnCounts.size < 8 * lights.length) {
      if (this.drawnCounts) this.drawnCounts.destroy();
      this.drawnCounts = this.buffer('umbra drawn counts', 8 * Math.max(4, lights.length), U.COPY_DST | U.COPY_SRC);
    }
    this.drawn = lights.map((_, k) => ({ culled: culled[k], casting: !!casting && !this.rays, triangles: s ? s.triangles : 0 }));
    if (culled.some(Boolean)) this.encodeSamples(encoder, lights, cull, culled);
    lights.forEach((_, k) => {
      const offset = [k * LIGHT_SLOT_BYTES];
      if (this.rays) {
        // ray-bvh (rays.js): the light's decision from its shadow rays, no volumes.
        if (k === 0) this.rays.encodeSamples(encoder);
        this.rays.encodeLight(encoder, k, offset, masks[k]);
        return;
      }
      const w0 = zpass[k] ?? null;
      const counted = w0 === null ? 0 : 1;
      if (casting) {
        encoder.copyBufferToBuffer(this.commandTemplate, 0, this.sidesCommand, 0, 16);
        encoder.copyBufferToBuffer(this.commandTemplate, 0, this.capsCommand, 0, 16);
        encoder.copyBufferToBuffer(this.commandTemplate, 0, this.fanCommands, 0, 16);
        encoder.copyBufferToBuffer(this.commandTemplate, 0, this.fanCommands, 16, 16);
        if (culled[k]) this.encodeCull(encoder, k, offset, cull[k], w0 !== null);
        let pass = encoder.beginComputePass({ label: `umbra light ${k} silhouettes` });
        pass.setBindGroup(0, this.lightGroup, offset);
        pass.setPipeline(this.transformPipeline);
        pass.setBindGroup(1, s.transformGroup);
        pass.dispatchWorkgroups(...dispatchSize(s.vertices));
        // z-pass: no caps (the caps command stays at 0 vertices, so classify lists none).
        if (culled[k]) {
          pass.setPipeline(w0 === null ? this.orientKeptPipeline : this.orientKeptOnlyPipeline);
          pass.setBindGroup(1, s.orientKeptGroup);
        } else {
          pass.setPipeline(w0 === null ? this.orientPipeline : this.orientOnlyPipeline);
          pass.setBindGroup(1, s.orientGroup);
        }
        pass.dispatchWorkgroups(...dispatchSize(s.triangles));
        if (s.recordCount > 0) {
          pass.setPipeline(this.sidesPipeline);
          pass.setBindGroup(1, s.sidesGroup);
          pass.dispatchWorkgroups(...dispatchSize(s.recordCount));
        }
        // What the light's volume drew, for readVolumes: the triangles the cull kept and the
        // side vertices (6 per quad), before the next light's passes reuse both buffers.
        pass.end();
        encoder.copyBufferToBuffer(s.needed, 0, this.drawnCounts, 8 * k, 4);
        encoder.copyBufferToBuffer(this.sidesCommand, 0, this.drawnCounts, 8 * k + 4, 4);
        pass = encoder.beginComputePass({ label: `umbra light ${k} polygons` });
        pass.setBindGroup(0, this.lightGroup, offset);
        // Over every polygon there may be; each invocation past the compacted counts returns.
        pass.setPipeline(this.classifyPipeline);
        pass.setBindGroup(1, s.classifyGroup);
        pass.setBindGroup(2, s.classifyUniformGroup);
        pass.dispatchWorkgroups(...dispatchSize(s.polygons));
        pass.end();
      }
      const pass = encoder.beginRenderPass({
        label: `umbra light ${k} volumes`,
        // Cleared to 0, shadowed: the mask pass writes the lit pixels.
        colorAttachments: [{ view: masks[k], clearValue: { r: 0, g: 0, b: 0, a: 0 }, loadOp: 'clear', storeOp: 'store' }],
        // The scene's depth kept; the count starts at 0 (z-fail) or at the eye's count W0 mod
        // 256 (z-pass).
        depthStencilAttachment: { view: t.view, depthLoadOp: 'load', depthStoreOp: 'store', stencilClearValue: w0 === null ? 0 : ((w0 % 256) + 256) % 256, stencilLoadOp: 'clear', stencilStoreOp: 'discard' },
      });
      if (casting) {
        pass.setBindGroup(0, this.lightGroup, offset);
        pass.setPipeline(this.insideDraw[counted]);
        pass.setBindGroup(1, s.insideGroup);
        pass.drawIndirect(this.fanCommands, 0);
        pass.setPipeline(this.crossingDraw[counted]);
        pass.setBindGroup(1, s.crossingGroup);
        pass.drawIndirect(this.fanCommands, 16);
      }
      pass.setPipeline(this.maskPipeline);
      pass.setStencilReference(0);
      pass.draw(3);
      if (s && s.indexCount > 0) {
        pass.setPipeline(this.facingPipeline);
        pass.setBindGroup(0, this.lightGroup, offset);
        pass.setBindGroup(1, s.surfaceGroup);
        pass.draw(s.indexCount);
      }
      pass.end();
    });
    this.device.queue.submit([encoder.finish()]);
  }

  /**
   * The GPU cull's per-frame part: the lights' uniforms written (slot k of `cullUniforms`), then
   * the samples pass into the samples texture (made at the target's size).
   */
  encodeSamples(encoder, lights, cull, culled) {
    const s = this.scene;
    const t = this.target;
    if (!this.cullUniforms || this.cullUniforms.size < LIGHT_SLOT_BYTES * lights.length) {
      if (this.cullUniforms) this.cullUniforms.destroy();
      this.cullUniforms = this.buffer('umbra cull grids', LIGHT_SLOT_BYTES * Math.max(4, lights.length), U.UNIFORM | U.COPY_DST);
      this.cullGroups = new Map();
    }
    const words = new Uint32Array((LIGHT_SLOT_BYTES / 4) * lights.length);
    lights.forEach((_, k) => {
      if (culled[k]) words.set(cull[k], (LIGHT_SLOT_BYTES / 4) * k);
    });
    this.device.queue.writeBuffer(this.cullUniforms, 0, words);
    if (!this.samplesTexture) {
      const texture = this.device.createTexture({ label: 'umbra samples', size: [t.width, t.height], format: 'rgba32uint', usage: GPUTextureUsage.RENDER_ATTACHMENT | GPUTextureUsage.TEXTURE_BINDING });
      this.samplesTexture = { texture, view: texture.createView(), bytes: 16 * t.width * t.height, scene: null };
    }
    const st = this.samplesTexture;
    // Bind groups of this scene and samples texture (made again when either changes).
    if (s.cullGroup === undefined || s.cullUniforms !== this.cullUniforms) {
      s.cullUniforms = this.cullUniforms;
      s.cullGroup = this.device.createBindGroup({
        layout: this.cullLayout,
        entries: [
          { binding: 0, resource: { buffer: this.cullUniforms, size: 4 * CULL_WORDS } },
          ...[this.cells, s.positions, s.indices, s.pieces, s.needed].map((buffer, i) => ({ binding: i + 1, resource: { buffer } })),
        ],
      });
    }
    if (st.scene !== s) {
      st.scene = s;
      st.group = this.device.createBindGroup({ layout: this.scatterLayout, entries: [{ binding: 0, resource: st.view }, { binding: 1, resource: { buffer: s.normals } }] });
    }
    const pass = encoder.beginRenderPass({
      label: 'umbra samples',
      colorAttachments: [{ view: st.view, clearValue: { r: NO_SAMPLE, g: NO_SAMPLE, b: NO_SAMPLE, a: NO_SAMPLE }, loadOp: 'clear', storeOp: 'store' }],
      // Reason: the depth pass's depth, read (depth EQUAL), not changed.
      depthStencilAttachment: { view: t.view, depthReadOnly: true, stencilReadOnly: true },
    });
    pass.setPipeline(this.samplesPipeline);
    pass.setBindGroup(0, this.lightGroup, [0]);
    pass.setBindGroup(1, s.surfaceGroup);
    pass.draw(s.indexCount);
    pass.end();
  }

  /**
   * Light `k`'s cull (`words`: its uniform): its samples scattered into the map, the near
   * pyramid's cells raised under z-pass (`zpass`), the max pyramid built, the pieces needed
   * marked.
   */
  encodeCull(encoder, k, offset, words, zpass) {
    const s = this.scene;
    const t = this.target;
    // Reason: every cell empty (the word 0 is below every encoded value), no piece needed yet.
    encoder.clearBuffer(this.cells, 0, 4 * this.cullOffsets[1]);
    encoder.clearBuffer(s.needed);
    const pass = encoder.beginComputePass({ label: `umbra light ${k} cull` });
    const grid = [k * LIGHT_SLOT_BYTES];
    pass.setBindGroup(0, this.lightGroup, offset);
    pass.setBindGroup(1, s.cullGroup, grid);
    pass.setBindGroup(2, this.cullLevelGroup, [0]);
    pass.setBindGroup(3, this.samplesTexture.group);
    pass.setPipeline(this.scatterPipeline);
    pass.dispatchWorkgroups(...dispatchSize(t.width * t.height));
    // Each dispatch is its own synchronisation scope: each step reads the one before.
    if (zpass) {
      const [i0, i1, j0, j1] = words.subarray(24, 28);
      pass.setPipeline(this.raisePipeline);
      pass.dispatchWorkgroups(...dispatchSize((i1 - i0 + 1) * (j1 - j0 + 1)));
    }
    const faces = words[31];
    pass.setPipeline(this.reducePipeline);
    for (let level = 1; level < this.cullLevels; level++) {
      pass.setBindGroup(2, this.cullLevelGroup, [(level - 1) * LIGHT_SLOT_BYTES]);
      const side = CULL_SIDE >> level;
      pass.dispatchWorkgroups(...dispatchSize(faces * side * side));
    }
    pass.setBindGroup(2, this.cullLevelGroup, [0]);
    pass.setPipeline(this.needPipeline);
    pass.dispatchWorkgroups(...dispatchSize(s.triangles));
    pass.end();
  }

  /**
   * What each light's volume drew in the last frame, read back: [{ culled, triangles (kept by
   * the cull, or all the casters' when not culled), edges (side quads, one per unit of |m|) }],
   * as native umbra's DrawnVolume; empty with `rays`.
   */
  async readVolumes() {
    if (this.rays || !this.drawnCounts || this.drawn.length === 0) return [];
    const drawn = this.drawn;
    const buffer = this.device.createBuffer({ label: 'umbra drawn counts read-back', size: 8 * drawn.length, usage: U.COPY_DST | U.MAP_READ });
    const encoder = this.device.createCommandEncoder();
    encoder.copyBufferToBuffer(this.drawnCounts, 0, buffer, 0, 8 * drawn.length);
    this.device.queue.submit([encoder.finish()]);
    await buffer.mapAsync(GPUMapMode.READ);
    const words = Uint32Array.from(new Uint32Array(buffer.getMappedRange()));
    buffer.unmap();
    buffer.destroy();
    return drawn.map((d, k) => ({
      culled: d.culled,
      triangles: d.culled ? words[2 * k] : d.triangles,
      edges: d.casting ? words[2 * k + 1] / 6 : 0,
    }));
  }

  /** Clears every mask view to lit (a frame umbra did not draw). */
  clearMasks(views) {
    const encoder = this.device.createCommandEncoder({ label: 'umbra masks cleared' });
    for (const view of views) encoder.beginRenderPass({ colorAttachments: [{ view, clearValue: { r: 1, g: 1, b: 1, a: 1 }, loadOp: 'clear', storeOp: 'store' }] }).end();
    this.device.queue.submit([encoder.finish()]);
  }

  /** Light mask `texture` (r8unorm GPUTexture, the target's size) as rows top-down, 255 lit / 0 shadowed. */
  async readMask(texture) {
    const { width, height } = texture;
    const bytesPerRow = Math.ceil(width / 256) * 256;
    const buffer = this.device.createBuffer({ label: 'umbra mask read-back', size: bytesPerRow * height, usage: U.COPY_DST | U.MAP_READ });
    const encoder = this.device.createCommandEncoder();
    encoder.copyTextureToBuffer({ texture }, { buffer, bytesPerRow }, [width, height]);
    this.device.queue.submit([encoder.finish()]);
    await buffer.mapAsync(GPUMapMode.READ);
    const rows = new Uint8Array(buffer.getMappedRange());
    const out = new Uint8Array(width * height);
    for (let y = 0; y < height; y++) out.set(rows.subarray(y * bytesPerRow, y * bytesPerRow + width), y * width);
    buffer.unmap();
    buffer.destroy();
    return out;
  }

  dispose() {
    this.disposeScene();
    if (this.rays) this.rays.dispose();
    if (this.target) this.target.texture.destroy();
    if (this.uniforms) this.uniforms.destroy();
    if (this.cullUniforms) this.cullUniforms.destroy();
    if (this.drawnCounts) this.drawnCounts.destroy();
    if (this.samplesTexture) this.samplesTexture.texture.destroy();
    for (const b of [this.commandTemplate, this.sidesCommand, this.capsCommand, this.fanCommands, this.cells, this.cullLevelBuffer]) b.destroy();
    this.target = null;
    this.uniforms = null;
  }
}
