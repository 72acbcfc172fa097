// The orientation pass: every triangle's orientation towards the light, ONCE per light and
// frame (paper 001 Alg. 4 through the reference edge, multiplicity.wgsl), stored as one i32
// per triangle. Every later stage reads this value and nothing else: the side multiplicities
// (cs-silhouette's sides.wgsl, vs-silhouette's sides vertex shader: 001 Alg. 3 is the sum over
// an edge's triangles of +-orientation, umbra_geom::silhouette::TriangleSlots) and the caps.
// WGSL has no `precise`, so this is what keeps sides and caps consistent whatever the driver
// contracts (see multiplicity.wgsl).
//
// Two entry points over the same bindings:
//   orient:          the orientations only (vs-silhouette draws every triangle's cap slots);
//   orient_and_caps: also compacts the caps for an indirect draw (cs-silhouette, the twin of
//                    umbra-gl's cs_silhouette/caps.comp.glsl): an edge-on triangle
//                    (orientation 0) gets no cap, every other one writes its three vertex
//                    indices wound to face the light, reserved with one atomicAdd on the caps
//                    draw command's vertex count (vertices_per_cap per cap);
//   orient_kept, orient_kept_and_caps: the same after the GPU cull (cull.wgsl): a triangle
//                    of a piece no visible sample needs gets orientation 0 (no side, no cap),
//                    and the triangles kept are counted.
// Prepended: volume.wgsl (the light slot `u`: light and u.triangles; umbra_item,
// DrawCommand), multiplicity.wgsl.

@group(1) @binding(0) var<storage, read> positions: array<f32>;
// The scene's index buffer: 3 vertex indices per triangle.
@group(1) @binding(1) var<storage, read> indices: array<u32>;
@group(1) @binding(2) var<storage, read_write> orientation: array<i32>;
@group(1) @binding(3) var<storage, read_write> caps_command: DrawCommand;
// Per cap: 3 vertex indices, the light cap's counter-clockwise order.
@group(1) @binding(4) var<storage, read_write> caps: array<u32>;
// The cull's (orient_kept entries only): per triangle its piece; word 0 the triangles kept,
// word 1 + p whether piece p is needed (cull.wgsl).
@group(1) @binding(5) var<storage, read> piece: array<u32>;
@group(1) @binding(6) var<storage, read_write> needed: array<atomic<u32>>;

fn umbra_position(i: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

fn umbra_orient(t: u32, kept: bool) -> i32 {
    let tri = vec3<u32>(indices[3u * t], indices[3u * t + 1u], indices[3u * t + 2u]);
    var o = umbra_triangle_orientation(umbra_position(tri.x), umbra_position(tri.y), umbra_position(tri.z), u.light);
    if !kept {
        o = 0;
    }
    orientation[t] = o;
    return o;
}

// Whether triangle t's piece is needed, counting it when it is.
fn umbra_kept(t: u32) -> bool {
    if atomicLoad(&needed[1u + piece[t]]) == 0u {
        return false;
    }
    atomicAdd(&needed[0], 1u);
    return true;
}

fn umbra_cap(t: u32, o: i32) {
    if o == 0 {
        return;
    }
    let tri = vec3<u32>(indices[3u * t], indices[3u * t + 1u], indices[3u * t + 2u]);
    // Facing away: swap two vertices (paper 003 Alg. 2, lines 5-6; cpu-silhouette's order).
    let wound = select(tri.xzy, tri, o > 0);
    let slot = 3u * (atomicAdd(&caps_command.vertex_count, u.vertices_per_cap) / u.vertices_per_cap);
    caps[slot] = wound.x;
    caps[slot + 1u] = wound.y;
    caps[slot + 2u] = wound.z;
}

@compute @workgroup_size(256)
fn orient(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let t = umbra_item(gid, groups);
    if t >= u.triangles {
        return;
    }
    _ = umbra_orient(t, true);
}

@compute @workgroup_size(256)
fn orient_and_caps(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let t = umbra_item(gid, groups);
    if t >= u.triangles {
        return;
    }
    umbra_cap(t, umbra_orient(t, true));
}

@compute @workgroup_size(256)
fn orient_kept(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let t = umbra_item(gid, groups);
    if t >= u.triangles {
        return;
    }
    _ = umbra_orient(t, umbra_kept(t));
}

@compute @workgroup_size(256)
fn orient_kept_and_caps(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let t = umbra_item(gid, groups);
    if t >= u.triangles {
        return;
    }
    umbra_cap(t, umbra_orient(t, umbra_kept(t)));
}
