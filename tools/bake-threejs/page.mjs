// Shows one baked glTF: framed as `relight render`'s default camera frames a scene
// (haarshift's Camera::framing: the bounding sphere filling a 40-degree vertical field of
// view, from 20 degrees above the horizon on the +Z side), no lights (the material is unlit),
// no tone mapping.
// `window.baked` reports what the loader made of the file once a frame is drawn.
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";

const params = new URLSearchParams(location.search);
const url = params.get("model") ?? "model.glb";
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.toneMapping = THREE.NoToneMapping;
document.body.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x202020);
window.baked = { ready: false, error: null };

new GLTFLoader().load(
  url,
  (gltf) => {
    scene.add(gltf.scene);
    const box = new THREE.Box3().setFromObject(gltf.scene);
    const centre = box.getCenter(new THREE.Vector3());
    const radius = box.getSize(new THREE.Vector3()).length() / 2;
    const fov = 40;
    const camera = new THREE.PerspectiveCamera(fov, window.innerWidth / window.innerHeight,
      radius / 100, radius * 100);
    const distance = radius / Math.sin(THREE.MathUtils.degToRad(fov / 2));
    const up = THREE.MathUtils.degToRad(20);
    camera.position.set(centre.x, centre.y + distance * Math.sin(up), centre.z + distance * Math.cos(up));
    camera.lookAt(centre);
    renderer.render(scene, camera);
    const materials = [];
    gltf.scene.traverse((o) => {
      if (o.isMesh) {
        materials.push({
          type: o.material.type,
          vertexColors: o.material.vertexColors,
          colourAttribute: Boolean(o.geometry.attributes.color),
          vertices: o.geometry.attributes.position.count,
        });
      }
    });
    window.baked = { ready: true, error: null, materials, extras: gltf.asset.extras ?? null };
  },
  undefined,
  (error) => { window.baked = { ready: true, error: String(error) }; },
);
