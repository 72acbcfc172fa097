// The GPU cull of a silhouette method's volume: which pieces of the caster (triangles joined
// across shared edges, umbra_geom::silhouette::caster_pieces) may shadow a visible sample of
// this frame. CC shadow volumes (Lloyd, Wendt, Govindaraju, Manocha, EGSR 2004, Section 4.1)
// with the receivers taken from the frame itself: the light's receiver map
// (umbra_geom::receivers, scattered by receivers.wgsl into level 0 of `cells`) holds per
// light-space cell the largest distance (point light) or depth (directional) of a visible
// sample there, rounded up. A triangle can shadow only a sample in its frustum that lies
// farther than the triangle; when no cell its frustum may cover holds a value beyond the
// triangle's least value, no visible sample's count depends on it. A piece is needed when any
// of its triangles is; orientation.wgsl's orient_kept entries give the triangles of the other
// pieces orientation 0 (no side, no cap), so the silhouette is that of the pieces kept and
// no edge loses some of its triangles but not all. The proof: docs/exactness.md, "Volumes
// culled on the GPU".
//
// The twin of umbra_geom::receivers::ReceiverMap::cull_and_clamp's test, in f32 with bounds
// that only keep more: every cell rectangle is widened by twice the CPU's margin
// (RECEIVER_MARGIN; the f32 rounding of a cell coordinate is below 2^-22 of the grid), and
// the triangle's least value is a LOWER bound: for a point light the larger of the distance
// to the triangle's box and to its plane, each less its worst rounding, times (1 - 2^-16);
// for a directional light the least depth of its corners less 2^-18 of their magnitude.
//
// Four entry points, dispatched in this order per light:
//   raise:  under z-pass, the cells of the eye's near pyramid (umbra_geom's
//           ReceiverGrid::hull_raise, computed on the CPU) raised to its farthest value, so a
//           triangle whose frustum holds a point of it is kept: z-pass counts from there;
//   reduce: one level of the max pyramid (once per level, coarsest last);
//   need:   one invocation per triangle: its piece marked needed.
// Prepended: volume.wgsl (the light slot `u`: light, triangles; umbra_item), receiver_cell.wgsl.

struct CullGrid {
    // ReceiverGrid::Flat: origin, u, v, travel (xyz), lo (xy) and scale (zw).
    origin: vec4<f32>,
    u: vec4<f32>,
    v: vec4<f32>,
    travel: vec4<f32>,
    lo_scale: vec4<f32>,
    // Flat: the widening of a rectangle along u and v (xy), in the grid's units.
    margin: vec4<f32>,
    // The rectangle raised under z-pass: i0, i1, j0, j1 (inclusive).
    raise_rect: vec4<u32>,
    // Its face, and the value every cell there reaches (encoded).
    raise_face: u32,
    raise_word: u32,
    // Cells along a side of level 0, and faces (6 point, 1 directional).
    side: u32,
    faces: u32,
    // The number of the coarsest level (one cell per face).
    top: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
    // Word offset of each level of the pyramid in `cells`: level k at level_offset[k / 4][k % 4].
    level_offset: array<vec4<u32>, 4>,
}

// One level of the pyramid (a dynamic offset per level).
struct CullLevel {
    // Word offsets of the finer level read and the level written, and the written level's side.
    src: u32,
    dst: u32,
    side: u32,
    pad: u32,
}

@group(1) @binding(0) var<uniform> g: CullGrid;
// The pyramid: level 0 is the receiver map (ReceiverGrid's cells, encoded, 0 empty), then each
// coarser level, all faces of a level together, face-major.
@group(1) @binding(1) var<storage, read_write> cells: array<atomic<u32>>;
@group(1) @binding(2) var<storage, read> positions: array<f32>;
// The scene's index buffer: 3 vertex indices per triangle.
@group(1) @binding(3) var<storage, read> indices: array<u32>;
// Per triangle, its piece.
@group(1) @binding(4) var<storage, read> piece: array<u32>;
// Word 0: the triangles kept (orientation.wgsl counts them); word 1 + p: piece p is needed.
@group(1) @binding(5) var<storage, read_write> needed: array<atomic<u32>>;
@group(2) @binding(0) var<uniform> level: CullLevel;

fn cull_offset(k: u32) -> u32 {
    return g.level_offset[k / 4u][k % 4u];
}

@compute @workgroup_size(256)
fn raise(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let r = g.raise_rect;
    let width = r.y - r.x + 1u;
    let k = umbra_item(gid, groups);
    if k >= width * (r.w - r.z + 1u) {
        return;
    }
    let i = r.x + k % width;
    let j = r.z + k / width;
    atomicMax(&cells[(g.raise_face * g.side + j) * g.side + i], g.raise_word);
}

@compute @workgroup_size(256)
fn reduce(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let s = level.side;
    let k = umbra_item(gid, groups);
    if k >= g.faces * s * s {
        return;
    }
    let f = k / (s * s);
    let j = (k % (s * s)) / s;
    let i = k % s;
    let fine = 2u * s;
    let base = level.src + f * fine * fine + 2u * j * fine + 2u * i;
    let m = max(
        max(atomicLoad(&cells[base]), atomicLoad(&cells[base + 1u])),
        max(atomicLoad(&cells[base + fine]), atomicLoad(&cells[base + fine + 1u])),
    );
    atomicStore(&cells[level.dst + k], m);
}

fn cull_cell(x: f32, lo: f32, scale: f32) -> u32 {
    return receiver_cell(x, lo, scale, g.side);
}

// The largest word of face `face`'s cells i0..=i1 x j0..=j1 (r = i0, i1, j0, j1), read at the
// finest level where the rectangle spans at most 4 x 4 cells (a coarser cell bounds its finer
// cells): ReceiverMap::max_over.
fn cull_max_over(face: u32, r: vec4<u32>) -> u32 {
    var k = 0u;
    while k < g.top && ((r.y >> k) - (r.x >> k) >= 4u || (r.w >> k) - (r.z >> k) >= 4u) {
        k++;
    }
    let s = g.side >> k;
    let base = cull_offset(k) + face * s * s;
    var m = 0u;
    for (var j = r.z >> k; j <= (r.w >> k); j++) {
        for (var i = r.x >> k; i <= (r.y >> k); i++) {
            m = max(m, atomicLoad(&cells[base + j * s + i]));
        }
    }
    return m;
}

// The largest word of the whole map (the coarsest level's cells).
fn cull_max_all() -> u32 {
    var m = 0u;
    for (var f = 0u; f < g.faces; f++) {
        m = max(m, atomicLoad(&cells[cull_offset(g.top) + f]));
    }
    return m;
}

fn cull_position(i: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * i], positions[3u * i + 1u], positions[3u * i + 2u]);
}

// A point light: the largest word of the cells the triangle's cone of directions (d0, d1, d2:
// its corners less the light) may cover: ReceiverGrid::cells_of on the cube, or the whole
// map where the cone does not lie within one face by 4 cells (or reaches the light).
fn cull_cube_bound(d0: vec3<f32>, d1: vec3<f32>, d2: vec3<f32>) -> u32 {
    let c = abs(d0 + d1 + d2);
    var m = 2u;
    if c.x >= c.y && c.x >= c.z {
        m = 0u;
    } else if c.y >= c.z {
        m = 1u;
    }
    let s = select(1.0, -1.0, (d0 + d1 + d2)[m] < 0.0);
    var lo = vec2<f32>(2.0);
    var hi = vec2<f32>(-2.0);
    for (var k = 0; k < 3; k++) {
        var d = d0;
        if k == 1 {
            d = d1;
        } else if k == 2 {
            d = d2;
        }
        let den = s * d[m];
        if !(den > 0.0) {
            return cull_max_all();
        }
        let uv = vec2<f32>(d[(m + 1u) % 3u], d[(m + 2u) % 3u]) / den;
        lo = min(lo, uv);
        hi = max(hi, uv);
    }
    let limit = 1.0 - 4.0 / f32(g.side);
    if lo.x < -limit || lo.y < -limit || hi.x > limit || hi.y > limit {
        return cull_max_all();
    }
    // Twice ReceiverMap's 2 * RECEIVER_MARGIN (1 / 16384 of the grid's extent 2).
    let margin = 4.0 / 16384.0;
    let scale = 0.5 * f32(g.side);
    let r = vec4<u32>(
        cull_cell(lo.x - margin, -1.0, scale),
        cull_cell(hi.x + margin, -1.0, scale),
        cull_cell(lo.y - margin, -1.0, scale),
        cull_cell(hi.y + margin, -1.0, scale),
    );
    return cull_max_over(2u * m + select(0u, 1u, s < 0.0), r);
}

// A lower bound of the distance from the light to the triangle a, b, c (d0 = a - light).
fn cull_point_least(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>, d0: vec3<f32>, d1: vec3<f32>, d2: vec3<f32>) -> f32 {
    // The triangle's box: per axis the distance from 0 to [lo, hi], each one of the corners'
    // own differences (rounded once), then a norm (a few roundings).
    let lo = min(d0, min(d1, d2));
    let hi = max(d0, max(d1, d2));
    let gap = max(max(lo, -hi), vec3<f32>(0.0));
    var least = sqrt(dot(gap, gap));
    // The triangle's plane: |n . d0| / |n| with n = (b - a) x (c - a). The computed unit normal
    // is off by at most ~2^-20 |b - a| |c - a| / |n| (the cross product's rounding, that of the
    // edges, and the normalisation), and d0 by 2^-24 of itself: 2^-17 of both is a bound with
    // room to spare; a sliver (|n| tiny against its edges) gets a bound below 0 and the box's
    // decides.
    let e1 = b - a;
    let e2 = c - a;
    let n = cross(e1, e2);
    let n_len = sqrt(dot(n, n));
    if n_len > 0.0 {
        let d_len = sqrt(dot(d0, d0));
        let e_len = sqrt(dot(e1, e1)) * sqrt(dot(e2, e2));
        let plane = abs(dot(n, d0)) / n_len;
        least = max(least, plane - d_len * (e_len / n_len + 1.0) / 131072.0);
    }
    return least * (1.0 - 1.0 / 65536.0);
}

@compute @workgroup_size(256)
fn need(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let t = umbra_item(gid, groups);
    if t >= u.triangles {
        return;
    }
    let a = cull_position(indices[3u * t]);
    let b = cull_position(indices[3u * t + 1u]);
    let c = cull_position(indices[3u * t + 2u]);
    var word: u32;
    var least: f32;
    if u.light.w != 0.0 {
        // The light's position as the scatter takes it (a point light's w is 1).
        let l = u.light.xyz;
        let d0 = a - l;
        let d1 = b - l;
        let d2 = c - l;
        word = cull_cube_bound(d0, d1, d2);
        least = cull_point_least(a, b, c, d0, d1, d2);
    } else {
        let r0 = a - g.origin.xyz;
        let r1 = b - g.origin.xyz;
        let r2 = c - g.origin.xyz;
        let cu = vec3<f32>(dot(r0, g.u.xyz), dot(r1, g.u.xyz), dot(r2, g.u.xyz));
        let cv = vec3<f32>(dot(r0, g.v.xyz), dot(r1, g.v.xyz), dot(r2, g.v.xyz));
        let lo = vec2<f32>(min(cu.x, min(cu.y, cu.z)), min(cv.x, min(cv.y, cv.z))) - g.margin.xy;
        let hi = vec2<f32>(max(cu.x, max(cu.y, cu.z)), max(cv.x, max(cv.y, cv.z))) + g.margin.xy;
        let r = vec4<u32>(
            cull_cell(lo.x, g.lo_scale.x, g.lo_scale.z),
            cull_cell(hi.x, g.lo_scale.x, g.lo_scale.z),
            cull_cell(lo.y, g.lo_scale.y, g.lo_scale.w),
            cull_cell(hi.y, g.lo_scale.y, g.lo_scale.w),
        );
        word = cull_max_over(0u, r);
        let depth = vec3<f32>(dot(r0, g.travel.xyz), dot(r1, g.travel.xyz), dot(r2, g.travel.xyz));
        let a0 = abs(r0);
        let a1 = abs(r1);
        let a2 = abs(r2);
        let magnitude = max(a0.x + a0.y + a0.z, max(a1.x + a1.y + a1.z, a2.x + a2.y + a2.z));
        least = min(depth.x, min(depth.y, depth.z)) - magnitude / 262144.0;
    }
    if word > receiver_encode(least) {
        atomicOr(&needed[1u + piece[t]], 1u);
    }
}
