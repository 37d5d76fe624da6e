// The page `subflow view` writes: plays a result's animated surface (one connectivity,
// positions per frame) coloured by flow magnitude, non-rigid flow or camera texture,
// with orbit controls, a frame slider, play/pause and the colour scale. Everything it
// needs is in the page (the data as JSON + base64 in #subflow-data, three.js bundled).
// URL parameters (for tests and links): ?frame=K (start paused at frame K),
// &colour=flow|nonrigid|texture, &benchmark=N (render N frames, report the mean time).
// #subflow-status receives a JSON status: {ready, open_ms, errors, frame, frame_ms}.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const status = { ready: false, errors: [] };
const statusElement = document.getElementById('subflow-status');
const publish = () => { statusElement.textContent = JSON.stringify(status); };
window.addEventListener('error', (event) => { status.errors.push(String(event.message)); publish(); });
const consoleError = console.error.bind(console);
console.error = (...args) => { status.errors.push(args.map(String).join(' ')); publish(); consoleError(...args); };

function decode(base64, Type) {
  const text = atob(base64);
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; ++i) bytes[i] = text.charCodeAt(i);
  return new Type(bytes.buffer);
}

const data = JSON.parse(document.getElementById('subflow-data').textContent);
const vertexCount = data.vertex_count, frameCount = data.frame_count;
const positions = decode(data.positions, Float32Array);  // frames × vertices × 3
const indices = decode(data.indices, Uint32Array);
const colourings = {};  // name → {magnitudes | rgb, scale}
for (const [name, c] of Object.entries(data.colourings)) {
  colourings[name] = { ...c, values: c.magnitudes ? decode(c.magnitudes, Float32Array) : decode(c.rgb, Uint8Array) };
}
const table = data.colour_table;  // 256 × [r, g, b] sRGB bytes

const params = new URLSearchParams(window.location.search);
let frame = Math.min(frameCount - 1, Math.max(0, parseInt(params.get('frame') ?? '0', 10) || 0));
let playing = !params.has('frame') && !params.has('benchmark');
let colouring = params.get('colour') in colourings ? params.get('colour') : Object.keys(colourings)[0];

const container = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(container.clientWidth, container.clientHeight);
renderer.setClearColor(0xf4f4f4);
container.appendChild(renderer.domElement);

const geometry = new THREE.BufferGeometry();
const position = new THREE.BufferAttribute(new Float32Array(vertexCount * 3), 3);
const colour = new THREE.BufferAttribute(new Float32Array(vertexCount * 3), 3);
position.setUsage(THREE.DynamicDrawUsage);
colour.setUsage(THREE.DynamicDrawUsage);
geometry.setAttribute('position', position);
geometry.setAttribute('color', colour);
geometry.setIndex(new THREE.BufferAttribute(indices, 1));
const material = new THREE.MeshLambertMaterial({ vertexColors: true, side: THREE.DoubleSide });
const mesh = new THREE.Mesh(geometry, material);
const scene = new THREE.Scene();
scene.add(mesh);
scene.add(new THREE.AmbientLight(0xffffff, 1.2));

// Camera: the whole sequence's bounding sphere in view, world up = data.up.
const box = new THREE.Box3().setFromArray(positions);
const sphere = box.getBoundingSphere(new THREE.Sphere());
const camera = new THREE.PerspectiveCamera(35, container.clientWidth / container.clientHeight, sphere.radius / 100, sphere.radius * 100);
camera.up.fromArray(data.up);
const side = new THREE.Vector3(1, 0, 0);
if (Math.abs(side.dot(camera.up)) > 0.9) side.set(0, 1, 0);
const away = side.sub(camera.up.clone().multiplyScalar(side.dot(camera.up))).normalize();
camera.position.copy(sphere.center).addScaledVector(away, sphere.radius * 3.2).addScaledVector(camera.up, sphere.radius * 1.2);
const headlight = new THREE.DirectionalLight(0xffffff, 1.6);
camera.add(headlight);
scene.add(camera);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.copy(sphere.center);
controls.update();

function srgbToLinear(c) { return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4); }
const linearTable = table.map((rgb) => rgb.map((c) => srgbToLinear(c / 255)));

function showFrame(f) {
  frame = f;
  position.array.set(positions.subarray(f * vertexCount * 3, (f + 1) * vertexCount * 3));
  position.needsUpdate = true;
  geometry.computeVertexNormals();
  const c = colourings[colouring];
  const out = colour.array;
  if (c.magnitudes) {
    const span = c.max > c.min ? c.max - c.min : 1;
    const values = c.values.subarray(f * vertexCount, (f + 1) * vertexCount);
    for (let v = 0; v < vertexCount; ++v) {
      const k = Math.min(255, Math.max(0, Math.round(((values[v] - c.min) / span) * 255)));
      out[3 * v] = linearTable[k][0]; out[3 * v + 1] = linearTable[k][1]; out[3 * v + 2] = linearTable[k][2];
    }
  } else {
    const rgb = c.values.subarray(f * vertexCount * 3, (f + 1) * vertexCount * 3);
    for (let i = 0; i < vertexCount * 3; ++i) out[i] = srgbToLinear(rgb[i] / 255);
  }
  colour.needsUpdate = true;
  slider.value = String(f);
  frameLabel.textContent = `frame ${data.frame_names[f]} (${f + 1}/${frameCount}, ${(f / data.fps).toFixed(3)} s)`;
  status.frame = f;
}

function drawScale() {
  const c = colourings[colouring];
  const scale = document.getElementById('scale');
  scale.style.display = c.magnitudes ? '' : 'none';
  if (!c.magnitudes) return;
  document.getElementById('scale-label').textContent = `${c.label} [${c.units}]`;
  document.getElementById('scale-max').textContent = (c.max * c.display_factor).toPrecision(3);
  document.getElementById('scale-min').textContent = (c.min * c.display_factor).toPrecision(3);
  const canvas = document.getElementById('scale-bar');
  const context = canvas.getContext('2d');
  for (let y = 0; y < canvas.height; ++y) {
    const [r, g, b] = table[Math.round(255 * (1 - y / (canvas.height - 1)))];
    context.fillStyle = `rgb(${r},${g},${b})`;
    context.fillRect(0, y, canvas.width, 1);
  }
}

const slider = document.getElementById('frame');
const frameLabel = document.getElementById('frame-label');
const playButton = document.getElementById('play');
const colourSelect = document.getElementById('colour');
slider.max = String(frameCount - 1);
for (const name of Object.keys(colourings)) colourSelect.add(new Option(colourings[name].title, name));
colourSelect.value = colouring;
document.getElementById('title').textContent = `${data.title}: ${frameCount} frames${data.stride > 1 ? ` (every ${data.stride}th)` : ''}, ${vertexCount} vertices, ${data.fps * (data.stride || 1)} fps`;
playButton.textContent = playing ? 'Pause' : 'Play';
slider.addEventListener('input', () => { playing = false; playButton.textContent = 'Play'; showFrame(parseInt(slider.value, 10)); });
playButton.addEventListener('click', () => { playing = !playing; playButton.textContent = playing ? 'Pause' : 'Play'; start = performance.now() - (frame / data.fps) * 1000; });
colourSelect.addEventListener('change', () => { colouring = colourSelect.value; drawScale(); showFrame(frame); });
window.addEventListener('resize', () => {
  camera.aspect = container.clientWidth / container.clientHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(container.clientWidth, container.clientHeight);
});

let start = performance.now();
function animate(now) {
  if (playing) {
    const f = Math.floor(((now - start) / 1000) * data.fps) % frameCount;
    if (f !== frame) showFrame(f);
  }
  controls.update();
  renderer.render(scene, camera);
  requestAnimationFrame(animate);
}

// Mean time of showing a frame (positions, normals, colours) and drawing it, forced to
// finish by reading a pixel back.
// update_ms is the share of showing the frame (JavaScript), the rest is drawing.
function benchmark(count) {
  const gl = renderer.getContext();
  const pixel = new Uint8Array(4);
  let update = 0;
  const begin = performance.now();
  for (let i = 0; i < count; ++i) {
    const before = performance.now();
    showFrame(i % frameCount);
    update += performance.now() - before;
    renderer.render(scene, camera);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
  }
  status.frame_ms = (performance.now() - begin) / count;
  status.update_ms = update / count;
  status.renderer = gl.getParameter(gl.RENDERER);
}

drawScale();
showFrame(frame);
renderer.render(scene, camera);
// From navigation start to the first frame drawn (parsing the page and its data included).
status.open_ms = performance.now();
if (params.has('benchmark')) {
  const shown = frame;
  benchmark(parseInt(params.get('benchmark'), 10) || 30);
  showFrame(shown);
  renderer.render(scene, camera);
}
status.ready = true;
publish();
requestAnimationFrame(animate);
