// hier-triangle, per light: the receiver map, the farthest live view sample from the light per
// light-space cell, which lets setup.comp.glsl drop every triangle whose shadow frustum can hold
// no live sample at all, before any node is tested. A triangle shadows a sample S only when the
// segment from S to the light meets it, so S lies in the triangle's cone of directions and
// farther from the light than the triangle (a point light: |S - L| greater than the triangle's
// least distance to L; a directional light: S's depth along the light beyond the least depth
// of the triangle's vertices). Most triangles of a detailed scene cast onto surfaces the eye
// does not see: every cell their cone covers holds only samples nearer the light than they
// are, or none, and they are dropped (their own samples lie no farther than the triangle, so
// they never keep it).
//
// Cells: a point light's directions on a cube of six RECEIVER_SIDE x RECEIVER_SIDE faces (the
// face of the direction's largest coordinate; the other two, divided by it, in [-1, 1]); a
// directional light's plane (u_light_u, u_light_v) over the union of the top nodes' boxes of
// their samples (hier/light_bounds.comp.glsl), RECEIVER_FLAT x RECEIVER_FLAT cells. A cell
// holds the largest value, order-preserving encoded for atomicMax, of each live sample's
// distance (point) or depth along the light (directional) rounded up by 2^-20 of the magnitudes
// involved, 0 where it holds none. The triangle's side (setup.comp.glsl) computes its cone's
// cells in double precision and widens them by RECEIVER_MARGIN of the grid, far more than the
// rounding of a sample's cell coordinates, so a live sample inside the cone is always in one of
// the cells tested. Prepended after live.glsl.

// RECEIVER_SIDE and RECEIVER_FLAT are defined by hier_triangle/mod.rs from layout.rs, whose
// RECEIVER_CELLS sizes the buffer.
const uint RECEIVER_CELLS = 6u * RECEIVER_SIDE * RECEIVER_SIDE;
// Where the directional grid's box is stored: four words after the cells.
const uint RECEIVER_BOX = RECEIVER_CELLS;
// The widening of a triangle's cell rectangle, as a fraction of the grid's extent.
const float RECEIVER_MARGIN = 1.0 / 16384.0;

// (The resolve's fragment shader, WORK_STUB, declares no storage block beyond its own.)
#ifndef WORK_STUB
layout(std430, binding = 10) coherent buffer Receivers { uint receivers[]; };
#endif

// receiver_encode, receiver_decode, receiver_cell, receiver_cube_cell: shared/receiver_cell.glsl,
// prepended before this file.

// A directional light's grid: the union of the top nodes' boxes (u0, u1, v0, v1), empty
// (u0 > u1) when no top node holds a sample. Computed once per light by the map's clearing
// pass and stored after the cells (receiver_box).
vec4 receiver_box_of_top_nodes() {
    vec4 box = vec4(3.0e38, -3.0e38, 3.0e38, -3.0e38);
    uint top = u_levels - 1u;
    uint count = u_level[top].x * u_level[top].y;
    for (uint k = 0u; k < count; ++k) {
        uint g = node_index(top, k);
        if (nodes[NODE_VEC4S * g].w <= nodes[NODE_VEC4S * g + 1u].w) {
            vec4 b = nodes[NODE_VEC4S * g + 2u];
            box = vec4(min(box.x, b.x), max(box.y, b.y), min(box.z, b.z), max(box.w, b.w));
        }
    }
    return box;
}

#ifndef WORK_STUB
// The stored directional grid's box; false when it is empty (no sample at all).
bool receiver_box(out vec4 box) {
    box = uintBitsToFloat(uvec4(receivers[RECEIVER_BOX], receivers[RECEIVER_BOX + 1u], receivers[RECEIVER_BOX + 2u],
                                receivers[RECEIVER_BOX + 3u]));
    return box.x <= box.y && box.z <= box.w;
}
#endif
