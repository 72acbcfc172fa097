// umbra-three's WebGPU volumes as polygons, and their clipping: what classify.wgsl and
// fan.wgsl share. A WGSL port of the WebGL path's src/webgl/glsl/clip.glsl (Sutherland &
// Hodgman 1974 in homogeneous clip space, Blinn & Newell 1978), for the same reason: SwiftShader
// (Chromium's WebGPU without a GPU, as its WebGL 2) re-projects the vertices of a triangle it
// clips, and at its 1/16-pixel snapping a vertex that a clipped and an unclipped volume triangle
// share can land on two grid points, which cracks the volume along the seam (docs/web.md, "Why
// umbra-three clips its volumes in the shader"). Crytek Sponza's default view at 640 x 360 had
// 487 samples outside the band with cs-silhouette's draws as they are; so every volume polygon
// that would reach the rasteriser's clipper is clipped here, to just inside the viewport, and
// light caps also to the camera's near plane (what native umbra's clip distance 0 does).
//
// The polygons of one light (cs-silhouette's compacted records; cs_draw.wgsl draws the same
// triangles unclipped): id = (index << 2) | kind,
//   kind 0, side quad `index` (quads[index] = (X, Y)): Y X X_inf Y_inf, cs_draw's quad, fanned
//           from the end umbra_later picks (Y X X_inf Y_inf or X X_inf Y_inf Y);
//   kind 1, light cap of cap `index`: P0 P1 P2 at w = 1, clipped by the near plane too, then
//           pushed to the far plane (paper 003 Eq. 6);
//   kind 2, dark cap of cap `index` (point lights): P2 P1 P0 at infinity.
// Prepended: volume.wgsl (the light slot `u`, umbra_push_to_far, umbra_near_distance).
// Bindings (group 1, 0-2) are each file's own: `clip`, `quads`, `caps` as in cs_draw.wgsl.

// 2^-15: the planes lie 1/32768 of the half-viewport inside its border: outside every pixel
// centre of viewports up to 16384 pixels, and far enough inside that rounding never puts a
// clipped vertex outside (clip.glsl).
const UMBRA_GUARD_MARGIN: f32 = 1.0 / 32768.0;
// A convex polygon gains at most one vertex per plane: a quad through 4 planes, a triangle
// through 5, end with at most 8.
const UMBRA_CLIP_MAX: u32 = 8u;

struct UmbraPolygon {
    v: array<vec4<f32>, 8>,
    n: u32,
    // Planes it is clipped by: 4 (the viewport's) or 5 (and the near plane: light caps).
    planes: u32,
    // A light cap: pushed to the far plane once clipped.
    push: bool,
}

// Whether clip position a comes after b, lexicographically on x, y, z, w (a total order on
// distinct points: the same for two casters' copies of one world point).
fn umbra_later(a: vec4<f32>, b: vec4<f32>) -> bool {
    if a.x != b.x {
        return a.x > b.x;
    }
    if a.y != b.y {
        return a.y > b.y;
    }
    if a.z != b.z {
        return a.z > b.z;
    }
    return a.w > b.w;
}

fn umbra_polygon(id: u32) -> UmbraPolygon {
    var p: UmbraPolygon;
    let kind = id & 3u;
    let index = id >> 2u;
    // Sides and dark caps: the viewport's 4 planes (a quad gains at most one vertex per plane:
    // 8 at most); their parts nearer than the near plane are depth-clamped, and lie in front
    // of every sample, where z-fail never counts.
    p.planes = 4u;
    p.push = false;
    if kind == 0u {
        let xy = quads[index];
        let x = clip[2u * xy.x];
        let y = clip[2u * xy.y];
        // The fan's apex is the edge's end that comes later in a fixed order of clip positions,
        // whichever way the quad runs (the sign of its multiplicity) and whichever caster it
        // belongs to: every quad on one edge is then split along the same diagonal (apex to the
        // other end at infinity), so quads meant to cancel (opposite signs on one edge: a split
        // record, coincident edges of two casters) cover exactly the same pixels, also where
        // the quad is a needle seen edge-on and its two diagonals round differently (the
        // WebGL path's polygons.vert.glsl fans from the record's B for the same reason).
        if umbra_later(x, y) {
            p.v[0] = x;
            p.v[1] = clip[2u * xy.x + 1u];
            p.v[2] = clip[2u * xy.y + 1u];
            p.v[3] = y;
        } else {
            p.v[0] = y;
            p.v[1] = x;
            p.v[2] = clip[2u * xy.x + 1u];
            p.v[3] = clip[2u * xy.y + 1u];
        }
        p.n = 4u;
    } else if kind == 1u {
        for (var k = 0u; k < 3u; k++) {
            p.v[k] = clip[2u * caps[3u * index + k]];
        }
        p.n = 3u;
        p.planes = 5u;
        p.push = true;
    } else {
        for (var k = 0u; k < 3u; k++) {
            p.v[k] = clip[2u * caps[3u * index + 2u - k] + 1u];
        }
        p.n = 3u;
    }
    return p;
}

// Signed distance of clip-space v to plane `plane` (0-3: left, right, bottom, top, just inside
// the viewport; 4: the camera's near plane), >= 0 inside. Every product is exact (a power of
// two), so no contraction can change it.
fn umbra_plane_distance(plane: u32, v: vec4<f32>) -> f32 {
    let inset = v.w * UMBRA_GUARD_MARGIN;
    switch plane {
        case 0u: { return (v.w + v.x) - inset; }
        case 1u: { return (v.w - v.x) - inset; }
        case 2u: { return (v.w + v.y) - inset; }
        case 3u: { return (v.w - v.y) - inset; }
        default: { return umbra_near_distance(v); }
    }
}

// The point where edge inside -> outside crosses the plane (d_in >= 0 > d_out), always from
// the inside end, so two polygons sharing an edge get the same cut vertex.
fn umbra_clip_edge(v_in: vec4<f32>, v_out: vec4<f32>, d_in: f32, d_out: f32) -> vec4<f32> {
    return (d_out * v_in - d_in * v_out) / (d_out - d_in);
}

// 0: every vertex inside every plane (drawn as it is); 1: all outside one plane (nothing
// left); 2: it crosses a plane (clipped).
fn umbra_classify(p: UmbraPolygon) -> u32 {
    var crosses = false;
    for (var plane = 0u; plane < p.planes; plane++) {
        var outside = 0u;
        for (var i = 0u; i < p.n; i++) {
            outside += select(0u, 1u, umbra_plane_distance(plane, p.v[i]) < 0.0);
        }
        if outside == p.n {
            return 1u;
        }
        crosses = crosses || outside > 0u;
    }
    return select(0u, 2u, crosses);
}

// Clips polygon p by its planes in order (clip.glsl umbra_clip); p.n < 3 after: nothing left.
fn umbra_clip(p_in: UmbraPolygon) -> UmbraPolygon {
    var p = p_in;
    for (var plane = 0u; plane < p.planes; plane++) {
        if p.n < 3u {
            break;
        }
        var d: array<f32, 8>;
        var any_out = false;
        for (var i = 0u; i < p.n; i++) {
            d[i] = umbra_plane_distance(plane, p.v[i]);
            any_out = any_out || d[i] < 0.0;
        }
        if !any_out {
            continue;
        }
        var kept: array<vec4<f32>, 8>;
        var at = 0u;
        for (var i = 0u; i < p.n; i++) {
            let j = select(0u, i + 1u, i + 1u < p.n);
            let in_i = d[i] >= 0.0;
            let in_j = d[j] >= 0.0;
            if in_i && at < UMBRA_CLIP_MAX {
                kept[at] = p.v[i];
                at++;
            }
            if in_i != in_j && at < UMBRA_CLIP_MAX {
                // Cut from the inside end, whichever way this polygon walks the edge.
                kept[at] = select(umbra_clip_edge(p.v[j], p.v[i], d[j], d[i]), umbra_clip_edge(p.v[i], p.v[j], d[i], d[j]), in_i);
                at++;
            }
        }
        p.v = kept;
        p.n = at;
    }
    return p;
}

// A light cap's vertex moved to the far plane after its clipping; any other vertex as it is.
fn umbra_drawn(p: UmbraPolygon, v: vec4<f32>) -> vec4<f32> {
    return select(v, umbra_push_to_far(v), p.push);
}
