// Diagnostic (URL parameter snap=N, docs/web.md): every vertex the rasteriser gets moved to the
// nearest 1/N pixel (ties to even, as SwiftShader rounds), so that an exact rasteriser
// (llvmpipe, 1/256 pixel) draws what one with log2(N) sub-pixel bits would: N = 16 emulates
// Chromium's SwiftShader. u_snap = 0 (the default): the position unchanged. Only points in
// front of the eye (w > 0) are moved; the rasteriser clips and snaps the rest itself. No
// #version line: spliced after the ES 3.00 prelude.

uniform float u_snap;
uniform vec2 u_viewport_size;

vec4 umbra_snap(vec4 clip) {
    if (u_snap == 0.0 || !(clip.w > 0.0)) {
        return clip;
    }
    vec2 window = (clip.xy / clip.w * 0.5 + 0.5) * u_viewport_size;
    window = roundEven(window * u_snap) / u_snap;
    return vec4(((window / u_viewport_size) * 2.0 - 1.0) * clip.w, clip.z, clip.w);
}
