// `ray-bvh` on umbra-three's WebGPU path (UmbraShadows option `method: 'ray-bvh'`): one shadow
// ray per visible sample through a BVH of the casters, native ray-bvh's walk and watertight
// test (umbra-wgpu's shaders/ray_bvh.wgsl, through the virtual module `umbra:wgsl`) over the
// hierarchy native ray-bvh builds (umbra_geom::ray_bvh::build, in the wasm: crates/umbra-wasm/
// src/ray_bvh.rs). No silhouettes and no stencil: per light, after passes.js's depth pass, one
// render pass draws every triangle again with depth EQUAL on the depth pass's surface (the
// facing pass's vertex stage, surface.wgsl vs_surface) and writes the decision into the light's
// mask (wgsl/ray.wgsl fs_ray).
//
// The BVH is built when the frame's merged geometry changes (world.js mergeParts: casters
// first), from the casters' triangles: a mesh that casts no shadow blocks no ray. Its records
// keep each caster triangle's number in the merged frame, which is the number the depth pass
// gives the same triangle, so a sample's ray skips its own triangle. The reference's eps is
// taken over every drawn position, as the oracle takes it over the scene it judges.
import WGSL from 'umbra:wgsl';
import SURFACE from './wgsl/surface.wgsl';
import RAY from './wgsl/ray.wgsl';

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
      ],
    });
    this.pipeline = null;
    this.constants = null;
    this.scene = null;
    /** The last BVH's figures: nodes, depth, build ms, bytes. */
    this.figures = null;
  }

  /** The pipeline for the walk's `constants` (the wasm's; the same for every BVH it builds). */
  pipelineFor(constants) {
    if (this.pipeline && this.constants === constants) return this.pipeline;
    const v = this.volumes;
    const module = this.device.createShaderModule({ label: 'umbra ray-bvh', code: ['enable clip_distances;', WGSL.volume, SURFACE, constants, WGSL.rayBvh, RAY].join('\n') });
    this.pipeline = this.device.createRenderPipeline({
      label: 'umbra ray-bvh',
      layout: this.device.createPipelineLayout({ bindGroupLayouts: [v.lightLayout, v.surfaceLayout, this.layout] }),
      vertex: { module, entryPoint: 'vs_surface' },
      fragment: { module, entryPoint: 'fs_ray', targets: [{ format: v.maskFormat }] },
      // Reason: the depth pass's primitive state (the same coverage and depths; both faces).
      primitive: { topology: 'triangle-list', cullMode: 'none', frontFace: 'ccw' },
      depthStencil: {
        format: v.depthFormat,
        // Reason: the depth pass's surface is kept for the next light.
        depthWriteEnabled: false,
        // Reason: exactly the depth pass's visible surface (the same vertex stage and state), so
        // each fragment is its pixel's visible sample.
        depthCompare: 'equal',
        // Reason: no count; the stencil is neither read nor written.
        stencilReadMask: 0,
        stencilWriteMask: 0,
      },
    });
    this.constants = constants;
    return this.pipeline;
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
    s.group = this.device.createBindGroup({ layout: this.layout, entries: [s.nodes, s.triangles, s.params].map((buffer, binding) => ({ binding, resource: { buffer } })) });
    s.pipeline = this.pipelineFor(bvh.constants);
    this.scene = s;
    this.figures = { nodes: bvh.nodeCount, depth: bvh.depth, buildMs, bytes: s.bytes };
  }

  disposeScene() {
    if (!this.scene) return;
    for (const k of ['nodes', 'triangles', 'params']) this.scene[k].destroy();
    this.scene = null;
  }

  /** Bytes of the BVH's buffers. */
  get gpuBytes() {
    return this.scene ? this.scene.bytes : 0;
  }

  /**
   * Light `k`'s decision into `mask` (a GPUTextureView, r8unorm) in `encoder`, after the depth
   * pass: lit where the sample's ray meets no caster and its seen side faces the light.
   */
  encodeLight(encoder, k, offset, mask) {
    const v = this.volumes;
    const pass = encoder.beginRenderPass({
      label: `umbra light ${k} rays`,
      // Cleared to lit: pixels without a sample (the background) are lit, as on the volume path
      // where no volume counts there; every sample's pixel is written by fs_ray.
      colorAttachments: [{ view: mask, clearValue: { r: 1, g: 1, b: 1, a: 1 }, loadOp: 'clear', storeOp: 'store' }],
      depthStencilAttachment: { view: v.target.view, depthLoadOp: 'load', depthStoreOp: 'store', stencilLoadOp: 'load', stencilStoreOp: 'store' },
    });
    const s = v.scene;
    if (this.scene && s && s.indexCount > 0) {
      pass.setPipeline(this.scene.pipeline);
      pass.setBindGroup(0, v.lightGroup, offset);
      pass.setBindGroup(1, s.surfaceGroup);
      pass.setBindGroup(2, this.scene.group);
      pass.draw(s.indexCount);
    }
    pass.end();
  }

  dispose() {
    this.disposeScene();
  }
}
