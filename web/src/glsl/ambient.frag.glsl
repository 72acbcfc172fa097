#version 300 es
// Pass 1 of the stencil shadow-volume frame (Heidmann 1991; Everitt & Kilgard 2002 §2): depth
// and the ambient term, albedo * ambient (port of shaders/depth_ambient.frag.glsl without the
// verification attachments). In the shadow-mask view u_ambient_color is black.
precision highp float;

in vec3 v_world_pos;
flat in vec3 v_normal;

uniform vec3 u_ambient_color;

out vec4 o_color;

void main() {
    o_color = vec4(u_ambient_color, 1.0);
}
