// Loads a glTF file with three.js's GLTFLoader (in Node, no browser, so no image decoder: the leaves'
// texture is skipped, a plugin answering null for it; it cuts the leaves' shape, not their motion), plays
// its first animation with an AnimationMixer and prints every skinned vertex in world space at the
// times asked for, as three.js skins them (SkinnedMesh.applyBoneTransform): {"<time>": [x, y, z, ...]}.
// three.js is found in NODE_PATH (an ES module does not search it by itself).
import fs from 'fs';
import path from 'path';
import { pathToFileURL } from 'url';

const three = (p) => import(pathToFileURL(path.join(process.env.NODE_PATH, 'three', p)).href);
const THREE = await three('build/three.module.js');
const { GLTFLoader } = await three('examples/jsm/loaders/GLTFLoader.js');

const [file, ...times] = process.argv.slice(2);
const bytes = fs.readFileSync(file);
const loader = new GLTFLoader();
loader.register(() => ({ name: 'treeanim_no_images', loadTexture: () => Promise.resolve(null) }));
loader.parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength), '', (gltf) => {
  const mixer = new THREE.AnimationMixer(gltf.scene);
  mixer.clipAction(gltf.animations[0]).play();
  const out = {};
  for (const t of times) {
    mixer.setTime(Number(t));
    gltf.scene.updateMatrixWorld(true);
    const verts = [];
    const v = new THREE.Vector3();
    gltf.scene.traverse((o) => {
      if (!o.isSkinnedMesh) return;
      o.skeleton.update();
      const pos = o.geometry.attributes.position;
      for (let i = 0; i < pos.count; i++) {
        o.applyBoneTransform(i, v.fromBufferAttribute(pos, i)).applyMatrix4(o.matrixWorld);
        verts.push(v.x, v.y, v.z);
      }
    });
    out[t] = verts;
  }
  console.log(JSON.stringify({ duration: gltf.animations[0].duration, vertices: out }));
}, (e) => { console.error(String(e)); process.exit(1); });
