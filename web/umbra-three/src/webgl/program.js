// WebGL 2 programs of umbra-three's drawer: compile and link with errors that name the shader file,
// and the active uniforms by name.

export class GlSetupError extends Error {}

function compile(gl, type, name, src) {
  const s = gl.createShader(type);
  gl.shaderSource(s, src);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) {
    const log = gl.getShaderInfoLog(s);
    gl.deleteShader(s);
    throw new GlSetupError(`${name}: compile failed: ${log}`);
  }
  return s;
}

/**
 * Links a program; returns { program, u } with u the active uniforms' locations by name.
 * `varyings`: vertex outputs captured by transform feedback, interleaved in that order.
 */
export function link(gl, name, vertName, vert, fragName, frag, varyings = null) {
  const p = gl.createProgram();
  const vs = compile(gl, gl.VERTEX_SHADER, vertName, vert);
  const fs = compile(gl, gl.FRAGMENT_SHADER, fragName, frag);
  gl.attachShader(p, vs);
  gl.attachShader(p, fs);
  if (varyings) gl.transformFeedbackVaryings(p, varyings, gl.INTERLEAVED_ATTRIBS);
  gl.linkProgram(p);
  gl.deleteShader(vs);
  gl.deleteShader(fs);
  if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new GlSetupError(`${name}: link failed: ${gl.getProgramInfoLog(p)}`);
  const u = {};
  const n = gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS);
  for (let i = 0; i < n; i++) {
    const info = gl.getActiveUniform(p, i);
    u[info.name] = gl.getUniformLocation(p, info.name);
  }
  return { program: p, u };
}
