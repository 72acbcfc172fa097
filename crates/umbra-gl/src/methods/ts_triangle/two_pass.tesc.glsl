// ts-triangle (two-pass per-triangle method): tessellation control shader, both passes.
// Paper 001, Section 2.1 and Alg. 1 / Fig. 2: a patch of the triangle's 3 points; volume pass
// (default): inner level 3, outer levels 1, which yields the 3 original corners and an inner
// triangle of 3 points that the evaluation shader extrudes (Alg. 1); light-cap pass
// (UMBRA_LIGHT_CAPS): all levels 1, a single triangle.
//
// Stage reason: one invocation per output control point decides, for the whole patch, whether
// and how the triangle casts. Orientation through the reference edge (Section 2.2-2.3,
// Alg. 2-4: umbra_triangle_orientation), so the volume agrees bit for bit with every other
// method's sides and caps: +1 keeps the vertex order, -1 swaps vertices 1 and 2 (the triangle
// is then wound to face the light, as its own light cap), 0 (edge-on or degenerate) sets the
// outer levels to 0, which discards the patch: it casts nothing.
//
// Volume pass only: invocation i also computes the canonical depth plane of the side of
// edge (i, i + 1) of the wound patch (shared/side_plane.glsl) for the fragment shader, which gives the
// side's fragments that depth so the two copies of a shared side cancel exactly.

layout(vertices = 3) out;

in vec3 v_world[];
out vec3 c_world[];
#ifndef UMBRA_LIGHT_CAPS
patch out dvec4 tc_side_plane[3];
#endif

uniform vec4 u_light;

void main() {
    int o = umbra_triangle_orientation(v_world[0], v_world[1], v_world[2], u_light);
    int source = (o < 0 && gl_InvocationID != 0) ? 3 - gl_InvocationID : gl_InvocationID;
    c_world[gl_InvocationID] = v_world[source];
#ifndef UMBRA_LIGHT_CAPS
    int next = gl_InvocationID == 2 ? 0 : gl_InvocationID + 1;
    int source_next = (o < 0 && next != 0) ? 3 - next : next;
    tc_side_plane[gl_InvocationID] = umbra_side_depth_plane(v_world[source], v_world[source_next], u_light);
#endif
    if (gl_InvocationID == 0) {
        float outer = o == 0 ? 0.0 : 1.0;
        gl_TessLevelOuter[0] = outer;
        gl_TessLevelOuter[1] = outer;
        gl_TessLevelOuter[2] = outer;
#ifdef UMBRA_LIGHT_CAPS
        gl_TessLevelInner[0] = 1.0;
#else
        gl_TessLevelInner[0] = 3.0;
#endif
    }
}
