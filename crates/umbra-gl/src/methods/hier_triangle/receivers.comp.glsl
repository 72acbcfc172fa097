// hier-triangle, per light: the receiver map (receivers.glsl). u_receiver_mode 0: one invocation
// per cell, cleared, and one more that stores the directional grid's box; 1: one invocation per pixel, its live sample (present, not facing away:
// init.comp.glsl's bit) raises its cell to its distance from the light (point) or its depth
// along the light (directional), rounded up. Prepended: hier/hierarchy.glsl, hier/region.glsl,
// frustum.glsl, live.glsl, shared/receiver_cell.glsl, receivers.glsl.

layout(local_size_x = 64) in;

uniform uint u_first;
uniform uint u_receiver_mode;

void main() {
    uint i = u_first + gl_GlobalInvocationID.x;
    if (u_receiver_mode == 0u) {
        if (i < RECEIVER_CELLS) {
            receivers[i] = 0u;
        } else if (i == RECEIVER_BOX) {
            uvec4 box = floatBitsToUint(receiver_box_of_top_nodes());
            receivers[RECEIVER_BOX] = box.x;
            receivers[RECEIVER_BOX + 1u] = box.y;
            receivers[RECEIVER_BOX + 2u] = box.z;
            receivers[RECEIVER_BOX + 3u] = box.w;
        }
        return;
    }
    if (i >= u_frame.x * u_frame.y) {
        return;
    }
    uvec2 at = uvec2(i % u_frame.x, i / u_frame.x);
    uint leaf = (at.y / LEAF_SIDE) * u_level[0].x + at.x / LEAF_SIDE;
    uint k = (at.y % LEAF_SIDE) * LEAF_SIDE + at.x % LEAF_SIDE;
    if ((state[live_word(0u, leaf)] & (1u << k)) == 0u) {
        return;
    }
    vec3 rel = uintBitsToFloat(samples[i].xyz) - u_origin;
    vec3 a = abs(rel);
    float magnitude = a.x + a.y + a.z;
    uint cell;
    float value;
    if (u_light.w != 0.0) {
        // A sample at the light is lit: no cell.
        if (!(magnitude > 0.0)) {
            return;
        }
        cell = receiver_cube_cell(rel, RECEIVER_SIDE);
        value = length(rel) * (1.0 + 1.0 / 1048576.0);
    } else {
        vec4 box;
        if (!receiver_box(box)) {
            return;
        }
        vec2 uv = vec2(dot(rel, u_light_u), dot(rel, u_light_v));
        vec2 scale = float(RECEIVER_FLAT) / max(vec2(box.y - box.x, box.w - box.z), vec2(1.0e-30));
        uint ci = receiver_cell(uv.x, box.x, scale.x, RECEIVER_FLAT);
        uint cj = receiver_cell(uv.y, box.z, scale.y, RECEIVER_FLAT);
        cell = cj * RECEIVER_FLAT + ci;
        value = -dot(rel, u_dir) + magnitude * (1.0 / 1048576.0);
    }
    atomicMax(receivers[cell], receiver_encode(value));
}
