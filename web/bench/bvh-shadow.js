// The exact alternative a three.js user has today: a shadow ray per pixel, traced in the
// fragment shader through three-mesh-bvh's GLSL BVH functions, written the way its
// documentation shows (MeshBVH over the scene's static world-space geometry from
// StaticGeometryGenerator, MeshBVHUniformStruct as the `BVH` uniform, BVHShaderGLSL's
// common_functions + bvh_struct_definitions + bvh_ray_functions, bvhIntersectFirstHit).
// three-mesh-bvh 0.9's GLSL offers no any-hit query: the shadow ray is its closest-hit
// (bvhIntersectFirstHit) toward the light, and the pixel is shadowed when the hit lies nearer
// than the light.
//
// Shading is MeshLambertMaterial's model (diffuse / pi times the ambient light plus the point
// light's cosine, no fall-off), so that it costs and looks as the other rows' material does.
import * as THREE from 'three';
import { BVHShaderGLSL, MeshBVH, MeshBVHUniformStruct, StaticGeometryGenerator } from 'three-mesh-bvh';

/**
 * Builds the BVH of every mesh under `root` (world space) and returns a ShaderMaterial that
 * shades with a shadow ray toward `light` (a PointLight), plus the BVH's triangle count.
 * `color`: the diffuse colour (sRGB hex, as a material's); `ambient`: the ambient light's
 * intensity (white); `offset`: how far along the normal the ray starts (against
 * self-intersection).
 */
export function bvhShadowMaterial(root, light, { color, ambient, offset }) {
  const meshes = [];
  root.traverse((o) => {
    if (o.isMesh) meshes.push(o);
  });
  // StaticGeometryGenerator merges indexed geometries or non-indexed ones, not a mix: where
  // the model mixes them, stand-ins with a 0..n-1 index for the non-indexed ones.
  const mixed = meshes.some((o) => o.geometry.index) && meshes.some((o) => !o.geometry.index);
  if (mixed) {
    for (const [k, o] of meshes.entries()) {
      if (o.geometry.index) continue;
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', o.geometry.attributes.position);
      g.setIndex([...Array(o.geometry.attributes.position.count).keys()]);
      const stand = new THREE.Mesh(g);
      stand.matrixWorld.copy(o.matrixWorld);
      stand.matrixAutoUpdate = false;
      stand.matrixWorldAutoUpdate = false;
      meshes[k] = stand;
    }
  }
  const generator = new StaticGeometryGenerator(meshes);
  generator.attributes = ['position'];
  const geometry = generator.generate();
  // One BVH root for the shader struct: the per-mesh groups the generator leaves go.
  geometry.clearGroups();
  const bvh = new MeshBVH(geometry);
  const uniform = new MeshBVHUniformStruct();
  uniform.updateFrom(bvh);
  const material = new THREE.ShaderMaterial({
    side: THREE.DoubleSide,
    uniforms: {
      bvh: { value: uniform },
      lightPosition: { value: new THREE.Vector3() },
      lightColor: { value: new THREE.Color() },
      diffuse: { value: new THREE.Color(color) },
      ambient: { value: new THREE.Color().setRGB(ambient, ambient, ambient) },
      offset: { value: offset },
    },
    vertexShader: /* glsl */ `
      varying vec3 vWorld;
      varying vec3 vNormal;
      void main() {
        vec4 world = modelMatrix * vec4(position, 1.0);
        vWorld = world.xyz;
        vNormal = normalize(mat3(modelMatrix) * normal);
        gl_Position = projectionMatrix * viewMatrix * world;
      }
    `,
    fragmentShader: /* glsl */ `
      precision highp isampler2D;
      precision highp usampler2D;
      #include <common>
      ${BVHShaderGLSL.common_functions}
      ${BVHShaderGLSL.bvh_struct_definitions}
      ${BVHShaderGLSL.bvh_ray_functions}
      uniform BVH bvh;
      uniform vec3 lightPosition;
      uniform vec3 lightColor;
      uniform vec3 diffuse;
      uniform vec3 ambient;
      uniform float offset;
      varying vec3 vWorld;
      varying vec3 vNormal;
      void main() {
        // The side facing the camera (both faces are drawn, as the other rows' DoubleSide).
        vec3 n = gl_FrontFacing ? normalize(vNormal) : -normalize(vNormal);
        vec3 toLight = lightPosition - vWorld;
        float lightDistance = length(toLight);
        vec3 direction = toLight / lightDistance;
        float cosine = max(dot(n, direction), 0.0);
        float lit = 0.0;
        // Facing away from the light: shadowed without a ray.
        if (cosine > 0.0) {
          uvec4 faceIndices;
          vec3 faceNormal;
          vec3 barycoord;
          float side;
          float dist;
          bool hit = bvhIntersectFirstHit(bvh, vWorld + n * offset, direction, faceIndices, faceNormal, barycoord, side, dist);
          lit = hit && dist < lightDistance ? 0.0 : 1.0;
        }
        gl_FragColor = vec4(diffuse * RECIPROCAL_PI * (ambient + lightColor * cosine * lit), 1.0);
        #include <colorspace_fragment>
      }
    `,
  });
  const update = () => {
    material.uniforms.lightPosition.value.setFromMatrixPosition(light.matrixWorld);
    material.uniforms.lightColor.value.copy(light.color).multiplyScalar(light.intensity);
  };
  return { material, update, triangles: bvh.geometry.index ? bvh.geometry.index.count / 3 : geometry.attributes.position.count / 3 };
}
