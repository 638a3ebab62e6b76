// voxfield's mesh viewer for the report pages: every element of class `voxfield-viewer` shows the
// glTF binary its `data-model` names, orbitable with the mouse (three.js's OrbitControls). The
// report is opened from disk (file://), where browsers refuse to fetch files or load ES modules,
// so this file is bundled into one classic script (build-report.mjs) and each model arrives as a
// classic script too, defining window.voxfieldModels[name] as base64: nothing is fetched.
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

function bytesOf(base64) {
  const text = atob(base64);
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; ++i) bytes[i] = text.charCodeAt(i);
  return bytes.buffer;
}

function fail(element, message) {
  element.dataset.state = 'error';
  element.textContent = message;
}

function mount(element) {
  const name = element.dataset.model;
  const base64 = (window.voxfieldModels || {})[name];
  if (!base64) return fail(element, `voxfield viewer: the model ${name} was not written beside this page`);
  const width = element.clientWidth || 960, height = element.clientHeight || 540;
  let renderer;
  try {
    // preserveDrawingBuffer: the picture stays readable (screenshots, the page's test).
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  } catch (e) {
    return fail(element, `voxfield viewer: this browser has no WebGL (${e.message})`);
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(width, height);
  element.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1c1e24);
  // voxfield's worlds are z-up; the light comes from above, a little from the side, as in the
  // CPU pictures of the report.
  scene.add(new THREE.HemisphereLight(0xdde6ff, 0x302820, 0.9));
  const sun = new THREE.DirectionalLight(0xffffff, 2.2);
  sun.position.set(-0.4, -0.5, 0.77);
  scene.add(sun);
  const camera = new THREE.PerspectiveCamera(42, width / height, 0.1, 1e6);
  camera.up.set(0, 0, 1);
  const controls = new OrbitControls(camera, renderer.domElement);
  const draw = () => renderer.render(scene, camera);
  controls.addEventListener('change', draw);
  new GLTFLoader().parse(bytesOf(base64), '', (gltf) => {
    scene.add(gltf.scene);
    // Frame the model: look at its centre from the front-left, above, at a distance that fits it.
    const box = new THREE.Box3().setFromObject(gltf.scene);
    const centre = box.getCenter(new THREE.Vector3());
    const radius = box.getSize(new THREE.Vector3()).length() / 2;
    const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 0.9;
    camera.position.copy(centre).add(new THREE.Vector3(-0.45, -0.75, 0.5).normalize().multiplyScalar(distance));
    camera.near = distance / 100;
    camera.far = distance * 10;
    camera.updateProjectionMatrix();
    controls.target.copy(centre);
    controls.update();
    let triangles = 0;
    gltf.scene.traverse((o) => {
      if (o.isMesh) triangles += (o.geometry.index ? o.geometry.index.count : o.geometry.attributes.position.count) / 3;
    });
    element.dataset.triangles = String(triangles);
    element.dataset.state = 'ready';
    draw();
  }, (error) => fail(element, `voxfield viewer: ${name} is not a glTF binary voxfield can show (${error.message || error})`));
}

document.querySelectorAll('.voxfield-viewer').forEach(mount);
