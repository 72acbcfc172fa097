// `ray-bvh` on umbra-three's WebGPU path (UmbraShadows option `method: 'ray-bvh'`): one shadow
// ray per visible sample through a BVH of the casters, native ray-bvh's walk and watertight
// test (umbra-wgpu's shaders/ray_bvh.wgsl, through the virtual module `umbra:wgsl`) over the
// hierarchy native ray-bvh builds (umbra_geom::ray_bvh::build, in the wasm: crates/umbra-wasm/
// src/ffi/ray_bvh.rs). No silhouettes and no stencil. After passes.js's depth pass, once per frame,
// every triangle is drawn again on the depth pass's surface (depth EQUAL, the facing pass's
// vertex stage, surface.wgsl vs_surface) into a samples texture (each pixel's world position,
// triangle and seen side: wgsl/ray.wgsl fs_sample); then per light one triangle over the
// viewport walks each pixel's ray and writes the decision into the light's mask (fs_ray).
//
// The BVH is built when the frame's merged geometry changes (world.js mergeParts: casters
// first), from the casters' triangles: a mesh that casts no shadow blocks no ray. Its records
// keep each caster triangle's number in the merged frame, which is the number the depth pass
// gives the same triangle, so a sample's ray skips its own triangle. The reference's eps is
// taken over every drawn position, as the oracle takes it over the scene it judges.
import WGSL from 'umbra:wgsl';
import SURFACE from './wgsl/surface.wgsl';
import MASK from './wgsl/mask.wgsl';
import RAY from './wgsl/ray.wgsl';
import SAMPLE_BITS from './wgsl/sample_bits.wgsl';
import SAMPLES from './wgsl/samples.wgsl';

/** Bytes of ray_bvh.wgsl's Params (eps, eps_near, nodes, pad). */
const PARAMS_BYTES = 16;

export class WebGPURays {
  /**
   * `volumes`: the WebGPUVolumes whose device, light slots, surface layout and depth target the
   * rays use; `geom`: the wasm module (loadUmbraGeom's), which builds the BVH.
   */
  constructor(volumes, geom) {
    this.volumes = volumes;
    this.geom = geom;
    this.device = volumes.device;
    this.layout = this.device.createBindGroupLayout({
      label: 'umbra ray-bvh',
      entries: [
        { binding: 0, visibility: GPUShaderStage.FRAGMENT, buffer: { type: 'read-only-storage' } },
        { binding: 1, visibility: GPUShaderStage.FRAGMENT, buffer: { type: 'read-only-storage' } },
        { binding: 2, visibility: GPUShaderStage.FRAGMENT, buffer: { type: 'uniform' } },
        { binding: 3, visibility: GPUShaderStage.FRAGMENT, texture: { sampleType: 'uint' } },
      ],
    });
    this.pipelines = null;
    this.constants = null;
    this.scene = null;
    this.samples = null;
    this.group = null;
    /** The last BVH's figures: nodes, depth, build ms, bytes. */
    this.figures = null;
  }

  /** The two pipelines for the walk's `constants` (the wasm's; the same for every BVH it builds). */
  pipelinesFor(constants) {
    if (this.pipelines && this.constants === constants) return this.pipelines;
    const v = this.volumes;
    const module = this.device.createShaderModule({ label: 'umbra ray-bvh', code: ['enable clip_distances;', WGSL.volume, SURFACE, MASK, constants, WGSL.rayBvh, SAMPLE_BITS, SAMPLES, RAY].join('\n') });
    const layout = (groups) => this.device.createPipelineLayout({ bindGroupLayouts: groups });
    this.pipelines = {
      // Pass 1: the visible samples. Reason for a layout without group 2: the samples texture
      // is this pass's attachment, and fs_sample reads nothing of group 2.
      sample: this.device.createRenderPipeline({
        label: 'umbra ray-bvh samples',
        layout: layout([v.lightLayout, v.surfaceLayout]),
        vertex: { module, entryPoint: 'vs_surface' },
        fragment: { module, entryPoint: 'fs_sample', targets: [{ format: 'rgba32uint' }] },
        // Reason: the depth pass's primitive state (the same coverage and depths; both faces).
        primitive: { topology: 'triangle-list', cullMode: 'none', frontFace: 'ccw' },
        depthStencil: {
          format: v.depthFormat,
          // Reason: the depth pass's surface is kept for the lights.
          depthWriteEnabled: false,
          // Reason: exactly the depth pass's visible surface (the same vertex stage and state),
          // so what a pixel keeps is its visible sample.
          depthCompare: 'equal',
          // Reason: no count; the stencil is neither read nor written.
          stencilReadMask: 0,
          stencilWriteMask: 0,
        },
      }),
      // Pass 2, per light: one fragment per pixel, no depth (the samples are its input).
      ray: this.device.createRenderPipeline({
        label: 'umbra ray-bvh rays',
        layout: layout([v.lightLayout, v.surfaceLayout, this.layout]),
        vertex: { module, entryPoint: 'vs_mask' },
        fragment: { module, entryPoint: 'fs_ray', targets: [{ format: v.maskFormat }] },
        primitive: { topology: 'triangle-list', cullMode: 'none' },
      }),
    };
    this.constants = constants;
    return this.pipelines;
  }

  /**
   * The BVH of `merged` (world.js mergeParts' frame: world positions, indices, casters' triangles
   * first, `casterTriangles` of them), uploaded. Throws the wasm's error on bad input.
   */
  setScene(merged) {
    this.disposeScene();
    const t0 = performance.now();
    const casterIndices = merged.indices.subarray(0, 3 * merged.casterTriangles);
    const bvh = this.geom.rayBvh(merged.positions, casterIndices);
    const buildMs = performance.now() - t0;
    const v = this.volumes;
    const S = GPUBufferUsage.STORAGE;
    const params = new ArrayBuffer(PARAMS_BYTES);
    new Float32Array(params, 0, 2).set([bvh.eps, 0.5 * bvh.eps]);
    new Uint32Array(params, 8, 2).set([bvh.nodeCount, 0]);
    const s = {
      nodes: v.buffer('umbra ray-bvh nodes', bvh.nodes.byteLength, S, bvh.nodes),
      triangles: v.buffer('umbra ray-bvh triangles', bvh.triangles.byteLength, S, bvh.triangles),
      params: v.buffer('umbra ray-bvh params', PARAMS_BYTES, GPUBufferUsage.UNIFORM, new Uint8Array(params)),
    };
    s.bytes = s.nodes.size + s.triangles.size + s.params.size;
    s.pipelines = this.pipelinesFor(bvh.constants);
    this.scene = s;
    this.group = null;
    this.figures = { nodes: bvh.nodeCount, depth: bvh.depth, buildMs, bytes: s.bytes };
  }

  disposeScene() {
    if (!this.scene) return;
    for (const k of ['nodes', 'triangles', 'params']) this.scene[k].destroy();
    this.scene = null;
  }

  /** Bytes of the BVH's buffers and the samples texture. */
  get gpuBytes() {
    return (this.scene ? this.scene.bytes : 0) + (this.samples ? this.samples.bytes : 0);
  }

  /** The samples texture at the depth target's size, and the group that binds it with the BVH. */
  prepareFrame() {
    const t = this.volumes.target;
    if (!this.samples || this.samples.width !== t.width || this.samples.height !== t.height) {
      if (this.samples) this.samples.texture.destroy();
      const texture = this.device.createTexture({ label: 'umbra ray-bvh samples', size: [t.width, t.height], format: 'rgba32uint', usage: GPUTextureUsage.RENDER_ATTACHMENT | GPUTextureUsage.TEXTURE_BINDING });
      this.samples = { texture, view: texture.createView(), width: t.width, height: t.height, bytes: 16 * t.width * t.height };
      this.group = null;
    }
    if (!this.group && this.scene) {
      const s = this.scene;
      this.group = this.device.createBindGroup({
        layout: this.layout,
        entries: [s.nodes, s.triangles, s.params].map((buffer, binding) => ({ binding, resource: { buffer } }))
          .concat([{ binding: 3, resource: this.samples.view }]),
      });
    }
  }

  /** Pass 1 in `encoder`, after the depth pass: every pixel's visible sample (or none). */
  encodeSamples(encoder) {
    this.prepareFrame();
    const v = this.volumes;
    const s = v.scene;
    const pass = encoder.beginRenderPass({
      label: 'umbra ray-bvh samples',
      // Cleared to "no sample" (ray.wgsl NO_SAMPLE in w).
      colorAttachments: [{ view: this.samples.view, clearValue: { r: 0, g: 0, b: 0, a: 0xffffffff }, loadOp: 'clear', storeOp: 'store' }],
      depthStencilAttachment: { view: v.target.view, depthLoadOp: 'load', depthStoreOp: 'store', stencilLoadOp: 'load', stencilStoreOp: 'store' },
    });
    if (this.scene && s && s.indexCount > 0) {
      pass.setPipeline(this.scene.pipelines.sample);
      // Slot 0: every slot holds the same clip_from_world.
      pass.setBindGroup(0, v.lightGroup, [0]);
      pass.setBindGroup(1, s.surfaceGroup);
      pass.draw(s.indexCount);
    }
    pass.end();
  }

  /**
   * Light `k`'s decision into `mask` (a GPUTextureView, r8unorm) in `encoder`, after
   * encodeSamples: lit where the sample's ray meets no caster and its seen side faces the
   * light, and where the pixel has no sample.
   */
  encodeLight(encoder, k, offset, mask) {
    const v = this.volumes;
    const s = v.scene;
    const pass = encoder.beginRenderPass({
      label: `umbra light ${k} rays`,
      colorAttachments: [{ view: mask, clearValue: { r: 1, g: 1, b: 1, a: 1 }, loadOp: 'clear', storeOp: 'store' }],
    });
    if (this.scene && this.group && s && s.indexCount > 0) {
      pass.setPipeline(this.scene.pipelines.ray);
      pass.setBindGroup(0, v.lightGroup, offset);
      pass.setBindGroup(1, s.surfaceGroup);
      pass.setBindGroup(2, this.group);
      pass.draw(3);
    }
    pass.end();
  }

  dispose() {
    this.disposeScene();
    if (this.samples) this.samples.texture.destroy();
    this.samples = null;
  }
}
