// The fan pass's fragment shader (fan.vert.glsl): the stencil counts, colour writes are off,
// and every fragment's depth is kept within the depths of its triangle's corners. No #version
// line: spliced after the ES 3.00 prelude.
//
// Why: llvmpipe sets a triangle's depth plane up in f32 from its corners, anchored at its first
// vertex, with a gradient error of about 2^-24 L^2 / 2A (L the longest side, A the area;
// docs/exactness.md, "The needle sides"), and a face of zero float area gets NaN. A shadow-volume
// side seen nearly edge-on is such a needle: Conference at 1280 x 720 (ANGLE on llvmpipe,
// reversed-Z) has hundreds of them, 330 pixels long and 1e-4 pixel wide, along the screen line
// through the light's projection; interpolated, some of their depths are nearer than the floor
// they lie far behind (8 false-shadow samples without this; web/test/needle.test.mjs). A depth
// interpolated inside a triangle lies between its corners' depths; one outside that range is the
// setup's error, so it is moved back to the nearest end of the range (a NaN to the smaller end).
// Where the rasteriser's depth is possible it stays as it is. Native umbra writes the face's
// plane depth in double instead (shared/face_depth.frag.glsl); GLSL ES 3.00 has no doubles, and
// a plane evaluated in float loses reversed-Z's tiny depths to cancellation. Writing
// gl_FragDepth makes llvmpipe test depth after the shader (lp_state_fs.c), as it does natively.

// (smallest, largest) window depth of the triangle's corners, slightly widened (fan.vert.glsl).
flat in vec2 v_depth_range;

#ifdef UMBRA_CULLED_FACES
// The true-depth light caps of one-sided casters (drawer.js, polygons.vert.glsl u_mode 3):
// only the fragments of triangles whose face on screen is the one the depth pass culls count.
// The cap is wound to face the light, so the triangle's own facing is gl_FrontFacing, reversed
// where its orientation is -1. u_keep_front: 1 where the depth pass culls front faces
// (BackSide), 0 where it culls back faces (FrontSide), in the volume pass's winding (glFrontFace
// CW for a mirroring matrix: the material's front is the caster's outward face either way).
// So a triangle the depth pass draws never counts here, the visible sample's own triangle
// included: its true-depth cap, at the sample's own depth, never meets the strict depth test.
uniform int u_keep_front;
flat in float v_orientation;
#endif

// The wide counter's output of the native fragment shader (vs_silhouette/volume.frag.glsl);
// ignored here: the colour write mask is off.
layout(location = 0) out float o_count;

void main() {
#ifdef UMBRA_CULLED_FACES
    bool triangle_front = gl_FrontFacing == (v_orientation > 0.0);
    if (triangle_front != (u_keep_front != 0)) {
        discard;
    }
#endif
    o_count = gl_FrontFacing ? 1.0 : -1.0;
    float z = gl_FragCoord.z;
    // NaN fails the first comparison and takes the range's smaller end.
    gl_FragDepth = z >= v_depth_range.x ? min(z, v_depth_range.y) : v_depth_range.x;
}
