// ts-triangle-1pass (single-pass per-triangle method): tessellation control shader.
// Paper 001, Section 2.1 and Fig. 3: the triangle "plus one more point to form a quad (four
// control shader invocations per patch)", tessellated with outer levels (1, 5, 1, 5), inner
// (5, 1) and fractional odd spacing (set in the evaluation shader's layout).
//
// Stage reason: as in two_pass.tesc.glsl, the whole patch is oriented once through the
// reference edge (Alg. 2-4, umbra_triangle_orientation): -1 swaps vertices 1 and 2 so the
// triangle faces the light, 0 discards the patch (outer levels 0). The fourth control point is
// the added quad corner; the evaluation shader places every tessellated vertex by its
// tessellation coordinate alone (one_pass.tese.glsl), so it carries a copy of the first point
// and is never read. Invocations 0..2 also compute the canonical depth plane of the side
// of edge (i, i + 1) of the wound triangle (shared/side_plane.glsl) for the fragment shader.

layout(vertices = 4) out;

in vec3 v_world[];
out vec3 c_world[];
patch out dvec4 tc_side_plane[3];

uniform vec4 u_light;

void main() {
    int o = umbra_triangle_orientation(v_world[0], v_world[1], v_world[2], u_light);
    int id = gl_InvocationID;
    int source = id == 3 ? 0 : ((o < 0 && id != 0) ? 3 - id : id);
    c_world[gl_InvocationID] = v_world[source];
    if (id < 3) {
        int next = id == 2 ? 0 : id + 1;
        int source_next = (o < 0 && next != 0) ? 3 - next : next;
        tc_side_plane[id] = umbra_side_depth_plane(v_world[source], v_world[source_next], u_light);
    }
    if (id == 0) {
        float on = o == 0 ? 0.0 : 1.0;
        gl_TessLevelOuter[0] = on;       // edge u = 0: one segment
        gl_TessLevelOuter[1] = 5.0 * on; // edge v = 0: five segments
        gl_TessLevelOuter[2] = on;       // edge u = 1
        gl_TessLevelOuter[3] = 5.0 * on; // edge v = 1
        gl_TessLevelInner[0] = 5.0;
        gl_TessLevelInner[1] = 1.0;
    }
}
