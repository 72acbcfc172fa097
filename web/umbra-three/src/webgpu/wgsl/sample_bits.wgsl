// The encoding of umbra-three's WebGPU samples texture (rgba32uint, one visible sample per
// pixel: samples.wgsl writes it; ray.wgsl's rays and scatter.wgsl's receiver map read it):
// x y z the world position's f32 bits, w the triangle, with the seen side in the top bit.

// A pixel without a sample: the texture is cleared to it (no triangle has this number).
const NO_SAMPLE: u32 = 0xffffffffu;
// The top bit of a sample's triangle word: its back side is the one seen.
const BACK_SEEN: u32 = 0x80000000u;
