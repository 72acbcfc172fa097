// ray-bvh, per frame: every pixel's sample set to "no sample" (triangle id 0xFFFFFFFF) before
// samples.frag.glsl writes the visible ones (background pixels get no fragment). 8 x 8 pixels
// per workgroup.

#version 450 core

layout(local_size_x = 8, local_size_y = 8) in;

layout(std430, binding = 3) writeonly buffer Samples { uvec4 samples[]; };

uniform uvec2 u_frame;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x < u_frame.x && p.y < u_frame.y) {
        samples[p.y * u_frame.x + p.x] = uvec4(0xFFFFFFFFu);
    }
}
