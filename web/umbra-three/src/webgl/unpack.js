// The unpack state umbra's uploads from typed arrays need: no unpack buffer, no flip, no
// premultiply, tight rows, no skips. three.js sets its own per texture it uploads and
// renderer.resetState() after umbra's frame makes it set them again.

/** Sets the plain unpack state on `gl`. */
export function plainUnpack(gl) {
  gl.bindBuffer(gl.PIXEL_UNPACK_BUFFER, null);
  gl.pixelStorei(gl.UNPACK_FLIP_Y_WEBGL, false);
  gl.pixelStorei(gl.UNPACK_PREMULTIPLY_ALPHA_WEBGL, false);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  gl.pixelStorei(gl.UNPACK_ROW_LENGTH, 0);
  gl.pixelStorei(gl.UNPACK_SKIP_ROWS, 0);
  gl.pixelStorei(gl.UNPACK_SKIP_PIXELS, 0);
}
