// The user's lit materials (MeshStandardMaterial, MeshPhysicalMaterial, MeshPhongMaterial,
// MeshLambertMaterial) receive umbra's decision in place of a shadow map: onBeforeCompile
// (chained after the user's own) multiplies each PointLight's and DirectionalLight's
// directLight.color by the decision of the pixel being shaded, read from umbra's mask target
// at gl_FragCoord (one channel per light; lights.js says which uniform is which light), and
// customProgramCacheKey (chained too) keeps patched programs apart from unpatched ones.
// The decision is per pixel: under MSAA every sample of a pixel gets its centre's decision.
import { ShaderChunk, Vector4 } from 'three';

/** Lights of one kind a program may have and umbra's select uniforms cover. */
export const MAX_SELECT = 64;

const KEY = 'umbra-three:1';

const DECLARATIONS = `
// umbra-three: the decision of light i is dot(mask, select_i) with select_i the unit vector of
// its channel, or 1 (lit) where select_i = 0 (a light umbra does not shadow).
uniform highp sampler2D umbraMask;
#if NUM_POINT_LIGHTS > 0
uniform vec4 umbraPointSelect[ NUM_POINT_LIGHTS ];
#endif
#if NUM_DIR_LIGHTS > 0
uniform vec4 umbraDirectionalSelect[ NUM_DIR_LIGHTS ];
#endif
float umbraLit( vec4 select ) {
	vec4 decision = texelFetch( umbraMask, ivec2( gl_FragCoord.xy ), 0 );
	return dot( decision, select ) + 1.0 - dot( select, vec4( 1.0 ) );
}
`;

/** three.js's lights_fragment_begin with umbra's decision after each light's info. */
export function patchedLightsChunk(chunk = ShaderChunk.lights_fragment_begin) {
  const point = 'getPointLightInfo( pointLight, geometryPosition, directLight );';
  const dir = 'getDirectionalLightInfo( directionalLight, directLight );';
  if (!chunk.includes(point) || !chunk.includes(dir)) {
    throw new Error('umbra-three: this three.js has no getPointLightInfo / getDirectionalLightInfo call in lights_fragment_begin; umbra-three needs three r187');
  }
  // `[ i ]` becomes the light's number when three.js unrolls the loop.
  return chunk
    .replace(point, `${point}\n\t\tdirectLight.color *= umbraLit( umbraPointSelect[ i ] );`)
    .replace(dir, `${dir}\n\t\tdirectLight.color *= umbraLit( umbraDirectionalSelect[ i ] );`);
}

/** The uniforms every patched material shares (their values change per frame). */
export function createUniforms(maskTexture) {
  const zeros = () => Array.from({ length: MAX_SELECT }, () => new Vector4(0, 0, 0, 0));
  return {
    umbraMask: { value: maskTexture },
    umbraPointSelect: { value: zeros() },
    umbraDirectionalSelect: { value: zeros() },
  };
}

/** Whether umbra patches `material`. */
export function isReceiverMaterial(material) {
  return !!material && (material.isMeshStandardMaterial || material.isMeshPhongMaterial || material.isMeshLambertMaterial);
}

/** Patches `material` once (a no-op for a patched or unsupported one). */
export function patchMaterial(material, uniforms, patched) {
  if (!isReceiverMaterial(material) || patched.has(material)) return;
  patched.add(material);
  const userCompile = material.onBeforeCompile;
  const userKey = material.customProgramCacheKey;
  material.onBeforeCompile = function onBeforeCompile(shader, renderer) {
    userCompile.call(this, shader, renderer);
    Object.assign(shader.uniforms, uniforms);
    const main = shader.fragmentShader.indexOf('void main()');
    if (main < 0 || !shader.fragmentShader.includes('#include <lights_fragment_begin>')) return; // a user shader umbra cannot see into: left unshadowed
    shader.fragmentShader = shader.fragmentShader.slice(0, main) + DECLARATIONS + shader.fragmentShader.slice(main)
      .replace('#include <lights_fragment_begin>', patchedLightsChunk());
  };
  material.customProgramCacheKey = function customProgramCacheKey() {
    return `${userKey.call(this)}|${KEY}`;
  };
  material.needsUpdate = true;
}
