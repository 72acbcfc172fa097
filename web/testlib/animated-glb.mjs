// An animated glTF for the glTF example's tests, written by three.js's own GLTFExporter in a
// page that has the example's import map (three, three/addons/): a floor, a two-bone skinned
// column (named "column") whose joint turns back and forth over 2 s, and three boxes of one
// InstancedMesh (named "boxes", EXT_mesh_gpu_instancing). Used by test/gltf.test.mjs (WebGL)
// and test/gltf-webgpu.test.mjs.

/** The .glb bytes (a Buffer), made in `page`. */
export async function makeAnimatedGlb(page) {
  const glb = await page.evaluate(async () => {
    const THREE = await import('three');
    const { GLTFExporter } = await import('three/addons/exporters/GLTFExporter.js');
    const scene = new THREE.Scene();
    const mat = new THREE.MeshStandardMaterial({ color: 0xcccccc });
    scene.add(new THREE.Mesh(new THREE.PlaneGeometry(8, 8).rotateX(-Math.PI / 2), mat));
    const g = new THREE.CylinderGeometry(0.25, 0.25, 2, 8, 4).translate(0, 1, 0);
    const p = g.attributes.position;
    const skinIndex = [];
    const skinWeight = [];
    for (let i = 0; i < p.count; i++) {
      skinIndex.push(p.getY(i) > 1 ? 1 : 0, 0, 0, 0);
      skinWeight.push(1, 0, 0, 0);
    }
    g.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(skinIndex, 4));
    g.setAttribute('skinWeight', new THREE.Float32BufferAttribute(skinWeight, 4));
    const root = new THREE.Bone();
    root.name = 'root';
    const joint = new THREE.Bone();
    joint.name = 'joint';
    joint.position.y = 1;
    root.add(joint);
    const column = new THREE.SkinnedMesh(g, mat);
    column.name = 'column';
    column.add(root);
    column.bind(new THREE.Skeleton([root, joint]));
    scene.add(column);
    const boxes = new THREE.InstancedMesh(new THREE.BoxGeometry(0.5, 0.5, 0.5), mat, 3);
    boxes.name = 'boxes';
    for (let i = 0; i < 3; i++) boxes.setMatrixAt(i, new THREE.Matrix4().makeTranslation(-2 + 2 * i, 0.25, 2));
    scene.add(boxes);
    const q = (a) => new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(0, 0, 1), a).toArray();
    const clip = new THREE.AnimationClip('bend', 2, [new THREE.QuaternionKeyframeTrack('joint.quaternion', [0, 1, 2], [...q(-1), ...q(1), ...q(-1)])]);
    const bytes = await new GLTFExporter().parseAsync(scene, { binary: true, animations: [clip] });
    let s = '';
    const u8 = new Uint8Array(bytes);
    for (let i = 0; i < u8.length; i += 8192) s += String.fromCharCode.apply(null, u8.subarray(i, i + 8192));
    return btoa(s);
  });
  return Buffer.from(glb, 'base64');
}
