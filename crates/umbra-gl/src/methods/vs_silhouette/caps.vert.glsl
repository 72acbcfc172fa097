// vs-silhouette: shadow-volume caps evaluated in the vertex shader from caps-data.
// Paper 003 (Milet et al., WebGL 1.0 shadows), Section 2.5, Algorithm 2, Eq. 6 (front cap
// shifted to infinity, z = w, through the shared depth.glsl umbra_push_to_far), Fig. 4-5;
// compact instanced layout of Section 2.6 (Eq. 9); orientation by paper 001's reference edge
// (Alg. 3-4) through the shared umbra_triangle_orientation, the same arithmetic as the sides.
//
// Common subset of GLSL 4.50 core and GLSL ES 3.00: no #version here (see sides.vert.glsl).
//
// One instance = one triangle (attribute divisor 1): its three vertices. The draw has 6
// vertices per instance for a point light (v = gl_VertexID: 0-2 the light ("front") cap,
// 3-5 the dark ("back") cap at infinity) and 3 for a directional light, whose dark cap has
// zero area (every vertex extrudes to the same point -L.xyz at infinity).

layout(location = 0) in vec4 a_p0;
layout(location = 1) in vec4 a_p1;
layout(location = 2) in vec4 a_p2;

uniform mat4 u_clip_from_world;
uniform vec4 u_light;

// Same expression as the scene vertex shader for the light cap's x, y, w (its screen
// footprint must be exactly the triangle's).
invariant gl_Position;

void main() {
    int v = gl_VertexID;
    vec3 p0 = a_p0.xyz;
    vec3 p1 = a_p1.xyz;
    vec3 p2 = a_p2.xyz;
    // Alg. 2, line 1: the triangle's orientation towards the light.
    int cur_mult = umbra_triangle_orientation(p0, p1, p2, u_light);
    if (cur_mult == 0) {
        // Alg. 2, lines 2-4: edge-on triangle, no cap (its edges' sides cancel too).
        gl_Position = vec4(0.0);
        return;
    }
    if (cur_mult < 0) {
        // Alg. 2, lines 5-6: wind the cap to face the light (swap two vertices).
        vec3 t = p1;
        p1 = p2;
        p2 = t;
    }
    // Light cap P0 P1 P2 (v < 3); dark cap P2 P1 P0 extruded (Alg. 2, line 11: P_{5-v}),
    // reversed so that it faces away from the volume's inside.
    int k = v < 3 ? v : 5 - v;
    vec3 p = k == 0 ? p0 : (k == 1 ? p1 : p2);
    if (v < 3) {
        // Alg. 2, lines 8-9 / Eq. 6: (V_x, V_y, V_w, V_w) through umbra_push_to_far.
        gl_Position = umbra_push_to_far(u_clip_from_world * vec4(p, 1.0));
    } else {
        gl_Position = u_clip_from_world * umbra_extrude(p, u_light);
    }
}
