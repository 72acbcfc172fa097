// The per-element pass of umbra-three (orientation.vert.glsl):
// the point's integer into its texel of the R8I target, as is. No depth, stencil or blending
// (volumes.js turns them off).

flat in int v_value;

layout(location = 0) out int o_value;

void main() {
    o_value = v_value;
}
