// mbdsim viewer: plays the scene JSON embedded in the page (element #mbdsim-data) with three.js.
// Exposes window.mbdsimViewer = {setTime(t), play(), pause(), time, duration, frames, ready, project(body)}.
// setTime(t) pauses playback, poses every body at time t [s] (interpolated between frames) and renders.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const data = JSON.parse(document.getElementById('mbdsim-data').textContent);
const T = data.time, N = T.length, t0 = T[0], t1 = T[N - 1];
const S = data.scale;
const $ = (id) => document.getElementById(id);

// ------------------------------------------------------------------ renderer, camera, lights
const view = $('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
view.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xf4f5f7);
const up = new THREE.Vector3(...data.up).normalize();
const camera = new THREE.PerspectiveCamera(40, 1, S * 1e-3, S * 200);
camera.up.copy(up);
scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8f99, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
scene.add(sun);

// ------------------------------------------------------------------ bodies
const groups = data.bodies.map((b) => {
  const g = new THREE.Group();
  g.name = b.name;
  g.add(shapeMesh(b.shape, b.color));
  scene.add(g);
  return g;
});
// centre-of-mass paths, when the scene asks for them (results tables: bodies are bare spheres)
if (data.trails) data.bodies.forEach((b) => {
  const geo = new THREE.BufferGeometry();
  geo.setAttribute('position', new THREE.BufferAttribute(new Float32Array(b.pos.map(Number)), 3));
  scene.add(new THREE.Line(geo, new THREE.LineBasicMaterial({ color: b.color, transparent: true, opacity: 0.5 })));
});
const ground = new THREE.Group();
scene.add(ground);
const holder = (k) => (k < 0 ? ground : groups[k]);

function material(color, opts = {}) {
  return new THREE.MeshStandardMaterial({ color, roughness: 0.55, metalness: 0.1, ...opts });
}

function shapeMesh(sh, color) {
  if (sh.kind === 'shapes') return new THREE.Group();   // drawn by its Body.add_shape shapes (data.shapes)
  const geo = sh.kind === 'box' ? new THREE.BoxGeometry(...sh.size) : new THREE.SphereGeometry(sh.radius, 32, 16);
  const mesh = new THREE.Mesh(geo, material(color));
  if (sh.quat) mesh.quaternion.set(...sh.quat);
  if (sh.center) mesh.position.set(...sh.center);
  return mesh;
}

// ------------------------------------------------------------------ joints, contact shapes, springs
const jointMat = material(0x222831);
for (const j of data.joints) {
  const m = new THREE.Mesh(new THREE.SphereGeometry(0.012 * S, 16, 8), jointMat);
  m.position.set(...j.local);
  m.name = 'joint:' + j.name;
  if (['revolute', 'cylindrical', 'translational', 'universal'].includes(j.kind)) {
    const len = 0.08 * S;
    const pin = new THREE.Mesh(new THREE.CylinderGeometry(0.004 * S, 0.004 * S, len, 8), jointMat);
    pin.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), new THREE.Vector3(...j.axis).normalize());
    m.add(pin);
  }
  holder(j.body).add(m);
}

for (const sh of data.shapes) {
  let mesh;
  if (sh.kind === 'mesh') {   // a shape placed with Body.add_shape, tessellated in body axes
    const geo = new THREE.BufferGeometry();
    geo.setAttribute('position', new THREE.Float32BufferAttribute(sh.vertices, 3));
    geo.setIndex(sh.faces);
    geo.computeVertexNormals();
    mesh = new THREE.Mesh(geo, material(sh.color || 0xb08d57, { transparent: true, opacity: 0.85, side: THREE.DoubleSide }));
    mesh.name = 'shape:' + (sh.body < 0 ? 'ground' : data.bodies[sh.body].name) + '.' + sh.name;
  } else if (sh.kind === 'sphere') {
    mesh = new THREE.Mesh(new THREE.SphereGeometry(sh.radius, 24, 12),
      new THREE.MeshBasicMaterial({ color: 0x333333, wireframe: true, transparent: true, opacity: 0.25 }));
  } else {
    mesh = new THREE.Mesh(new THREE.CircleGeometry(1.2 * S, 48),
      material(0x9aa5b1, { transparent: true, opacity: 0.45, side: THREE.DoubleSide }));
    mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), new THREE.Vector3(...sh.normal).normalize());
  }
  mesh.position.set(...sh.local);
  holder(sh.body).add(mesh);
}

const COILS = 12, COIL_PTS = COILS * 16 + 2;
const springs = data.springs.map((s) => {
  const n = s.kind === 'coil' ? COIL_PTS : 2;
  const geo = new THREE.BufferGeometry();
  geo.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * n), 3));
  const line = new THREE.Line(geo, new THREE.LineBasicMaterial({ color: 0xb03030 }));
  line.frustumCulled = false;
  scene.add(line);
  return { s, line, n };
});

const _a = new THREE.Vector3(), _b = new THREE.Vector3(), _d = new THREE.Vector3();
const _u = new THREE.Vector3(), _w = new THREE.Vector3();
function endPoint(e, out) {
  out.set(...e.local);
  return out.applyMatrix4(holder(e.body).matrixWorld);
}
function updateSprings() {
  for (const { s, line, n } of springs) {
    endPoint(s.i, _a); endPoint(s.j, _b);
    const p = line.geometry.attributes.position;
    if (n === 2) { p.setXYZ(0, _a.x, _a.y, _a.z); p.setXYZ(1, _b.x, _b.y, _b.z); }
    else {
      _d.subVectors(_b, _a);
      const L = _d.length() || 1e-12;
      _d.divideScalar(L);
      _u.set(1, 0, 0); if (Math.abs(_d.x) > 0.9) _u.set(0, 1, 0);
      _u.cross(_d).normalize(); _w.crossVectors(_d, _u);
      const r = 0.025 * S;
      p.setXYZ(0, _a.x, _a.y, _a.z);
      for (let k = 1; k < n - 1; k++) {
        const f = k / (n - 1), ang = 2 * Math.PI * COILS * f, c = r * Math.cos(ang), sn = r * Math.sin(ang);
        p.setXYZ(k, _a.x + _d.x * L * f + _u.x * c + _w.x * sn, _a.y + _d.y * L * f + _u.y * c + _w.y * sn,
          _a.z + _d.z * L * f + _u.z * c + _w.z * sn);
      }
      p.setXYZ(n - 1, _b.x, _b.y, _b.z);
    }
    p.needsUpdate = true;
  }
}

// contact forces (on request): an arrow per touching point along the force on shape_j, its tip at the point
// (it pushes on shape_j), drawn over the bodies
const CF = data.contact_forces, arrows = [];
const arrowGroup = new THREE.Group();
arrowGroup.name = 'contact-forces';
scene.add(arrowGroup);
function updateArrows(k, f) {
  if (!CF) return 0;
  const pts = CF.frames[N === 1 || f < 0.5 ? k : k + 1] || [];
  const n = pts.length / 6;
  while (arrows.length < n) {
    const a = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 1, 0xd62728);
    a.frustumCulled = false;
    a.renderOrder = 999;
    for (const part of [a.line, a.cone]) { part.material.depthTest = false; part.material.transparent = true; part.renderOrder = 999; }
    arrowGroup.add(a);
    arrows.push(a);
  }
  let shown = 0;
  arrows.forEach((a, i) => {
    if (i >= n) { a.visible = false; return; }
    _d.set(pts[6 * i + 3], pts[6 * i + 4], pts[6 * i + 5]);
    const len = Math.min(_d.length() * CF.scale, 0.3 * S);
    a.visible = len > 1e-6 * S;
    if (!a.visible) return;
    _d.normalize();
    a.position.set(pts[6 * i] - _d.x * len, pts[6 * i + 1] - _d.y * len, pts[6 * i + 2] - _d.z * len);
    a.setDirection(_d);
    a.setLength(len, Math.min(0.3 * len, 0.03 * S), Math.min(0.15 * len, 0.015 * S));
    shown += 1;
  });
  return shown;
}
let arrowsShown = 0;

// ------------------------------------------------------------------ floor grid and camera (placed by fitView)
const side = Math.abs(up.z) > 0.9 ? new THREE.Vector3(0, -1, 0) : new THREE.Vector3(0, 0, 1);
const right = new THREE.Vector3().crossVectors(up, side).normalize();
const controls = new OrbitControls(camera, renderer.domElement);
let grid = null;
scene.add(new THREE.AxesHelper(0.15 * S));

// ------------------------------------------------------------------ time, pose, signal
let time = t0, playing = true, speed = 1, last = null;
const _q0 = new THREE.Quaternion(), _q1 = new THREE.Quaternion();
function frameAt(t) {          // k, f with T[k] <= t <= T[k+1], f the fraction
  if (t <= T[0] || N === 1) return [0, 0];
  if (t >= T[N - 1]) return [N - 2, 1];
  let lo = 0, hi = N - 1;
  while (hi - lo > 1) { const mid = (lo + hi) >> 1; if (T[mid] <= t) lo = mid; else hi = mid; }
  return [lo, (t - T[lo]) / (T[lo + 1] - T[lo] || 1)];
}
function lerpAt(arr, stride, k, f, i) {
  return N === 1 ? arr[i] : arr[k * stride + i] * (1 - f) + arr[(k + 1) * stride + i] * f;
}
function pose(t) {
  const [k, f] = frameAt(t);
  data.bodies.forEach((b, i) => {
    const g = groups[i];
    g.position.set(lerpAt(b.pos, 3, k, f, 0), lerpAt(b.pos, 3, k, f, 1), lerpAt(b.pos, 3, k, f, 2));
    const k1 = N === 1 ? 0 : k + 1;
    _q0.fromArray(b.quat, 4 * k); _q1.fromArray(b.quat, 4 * k1);
    g.quaternion.slerpQuaternions(_q0, _q1, N === 1 ? 0 : f);
  });
  arrowsShown = updateArrows(k, f);
  scene.updateMatrixWorld(true);
  updateSprings();
  return [k, f];
}

const sig = data.signal, chart = $('chart');
function fmt(x) { return Math.abs(x) >= 1e4 || (Math.abs(x) < 1e-3 && x !== 0) ? x.toExponential(3) : x.toFixed(4); }
function showTime(t, k, f) {
  $('time').textContent = 't = ' + t.toFixed(3) + ' s';
  $('slider').value = String(Math.round(1000 * (t1 > t0 ? (t - t0) / (t1 - t0) : 0)));
  if (!sig) return;
  const vals = sig.series.map((s) => lerpAt(s.values, 1, k, f, 0));
  $('signal').textContent = sig.series.map((s, i) => s.name + ' = ' + fmt(vals[i])).join(',  ') + (sig.unit ? ' ' + sig.unit : '');
  drawChart(t);
}
const COLORS = ['#4e79a7', '#e15759', '#59a14f', '#f28e2b'];
function drawChart(t) {
  const c = chart.getContext('2d'), W = chart.width, H = chart.height;
  c.clearRect(0, 0, W, H);
  let lo = Infinity, hi = -Infinity;
  for (const s of sig.series) for (const v of s.values) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
  if (!(hi > lo)) { hi = lo + 1; lo -= 1; }
  const X = (x) => 4 + (W - 8) * (t1 > t0 ? (x - t0) / (t1 - t0) : 0), Y = (y) => H - 4 - (H - 8) * (y - lo) / (hi - lo);
  sig.series.forEach((s, i) => {
    c.strokeStyle = COLORS[i % COLORS.length]; c.lineWidth = 1.5; c.beginPath();
    s.values.forEach((v, n) => (n ? c.lineTo(X(T[n]), Y(v)) : c.moveTo(X(T[n]), Y(v))));
    c.stroke();
  });
  c.strokeStyle = '#222'; c.lineWidth = 1; c.beginPath(); c.moveTo(X(t), 0); c.lineTo(X(t), H); c.stroke();
  c.fillStyle = '#667'; c.font = '11px system-ui, sans-serif';
  c.fillText('max ' + fmt(hi), 6, 12); c.fillText('min ' + fmt(lo), 6, H - 6);
}

function render() { renderer.render(scene, camera); }
function setTime(t) {
  playing = false;
  $('play').textContent = '\u25B6 play';
  return show(Math.min(Math.max(Number(t), t0), t1));
}
function show(t) {
  time = t;
  const [k, f] = pose(t);
  showTime(t, k, f);
  render();
  return time;
}

// frame everything drawn over the whole motion: look from the front-right, a little above, at its
// centre, from the distance where its bounding sphere fills the view; the floor grid just below it
function fitView() {
  const box = new THREE.Box3(), step = Math.max(1, Math.floor(N / 60));
  for (let k = 0; k < N; k += step) { pose(T[k]); groups.forEach((g) => box.expandByObject(g)); }
  pose(T[N - 1]); groups.forEach((g) => box.expandByObject(g));
  data.joints.forEach((j) => { if (j.body < 0) box.expandByPoint(_a.set(...j.local)); });
  if (box.isEmpty()) box.expandByPoint(_a.set(0, 0, 0));
  const center = box.getCenter(new THREE.Vector3());
  const dir = new THREE.Vector3().addScaledVector(side, 1.5).addScaledVector(right, 0.5).addScaledVector(up, 0.45).normalize();
  const camUp = up.clone().addScaledVector(dir, -up.dot(dir)).normalize(), camRight = new THREE.Vector3().crossVectors(camUp, dir);
  const tv = Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2), th = tv * camera.aspect;
  let dist = 0.1 * S;     // the nearest distance at which every corner of the box is in view, plus a margin
  for (let c = 0; c < 8; c++) {
    _a.set(c & 1 ? box.max.x : box.min.x, c & 2 ? box.max.y : box.min.y, c & 4 ? box.max.z : box.min.z).sub(center);
    dist = Math.max(dist, _a.dot(dir) + Math.abs(_a.dot(camRight)) / th, _a.dot(dir) + Math.abs(_a.dot(camUp)) / tv);
  }
  dist *= 1.12;
  camera.position.copy(center).addScaledVector(dir, dist);
  camera.near = dist * 1e-3; camera.far = dist * 100; camera.updateProjectionMatrix();
  sun.position.copy(center).addScaledVector(side, 2 * dist).addScaledVector(up, 3 * dist).addScaledVector(right, dist);
  let lowest = Infinity;
  for (let c = 0; c < 8; c++) {
    _a.set(c & 1 ? box.max.x : box.min.x, c & 2 ? box.max.y : box.min.y, c & 4 ? box.max.z : box.min.z);
    lowest = Math.min(lowest, up.dot(_a));
  }
  // a floor about twice the size of the motion: it stays in front of the camera (lines crossing the
  // camera plane are lost by some software renderers)
  const size = 2 * Math.max(box.getSize(_a).length(), 0.1 * S);
  if (grid) scene.remove(grid);
  grid = new THREE.GridHelper(size, 20, 0xb8bec8, 0xd9dde3);
  grid.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), up);
  grid.position.copy(center).addScaledVector(up, lowest - up.dot(center) - 0.02 * S);
  scene.add(grid);
  controls.target.copy(center);
  controls.update();
}

// ------------------------------------------------------------------ controls and loop
$('title').textContent = data.title;
if (!sig) document.body.classList.add('nosignal');
$('play').addEventListener('click', () => (playing ? setTime(time) : play()));
$('slider').addEventListener('input', (e) => setTime(t0 + (t1 - t0) * Number(e.target.value) / 1000));
$('speed').addEventListener('change', (e) => { speed = Number(e.target.value); });
function play() {
  playing = true; last = null;
  $('play').textContent = '\u275A\u275A pause';
  if (time >= t1) time = t0;
}
function resize() {
  const w = view.clientWidth, h = view.clientHeight;
  renderer.setSize(w, h, false);
  renderer.domElement.style.width = '100%'; renderer.domElement.style.height = '100%';
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  if (sig) { chart.width = chart.clientWidth; chart.height = chart.clientHeight; drawChart(time); }
  render();
}
window.addEventListener('resize', resize);
controls.addEventListener('change', render);
function loop(now) {
  if (playing) {
    if (last !== null) { let t = time + speed * (now - last) / 1000; if (t > t1) t = t0 + (t - t1) % Math.max(t1 - t0, 1e-9); show(t); }
    last = now;
  } else last = null;
  requestAnimationFrame(loop);
}
resize();
fitView();
show(t0);
play();
requestAnimationFrame(loop);
// pixel position [x, y] (CSS pixels, page coordinates) of a body's centre of mass at the current time
function project(name) {
  const g = groups[data.bodies.findIndex((b) => b.name === name)];
  if (!g) throw new Error('no body named ' + name);
  const p = g.getWorldPosition(new THREE.Vector3()).project(camera), r = renderer.domElement.getBoundingClientRect();
  return [r.left + (p.x + 1) / 2 * r.width, r.top + (1 - p.y) / 2 * r.height];
}
window.mbdsimViewer = {
  setTime, play, pause: () => setTime(time), get time() { return time; }, get playing() { return playing; },
  duration: t1 - t0, start: t0, end: t1, frames: N, ready: true, project, scene, camera, render,
  get contactArrows() { return arrowsShown; },   // arrows drawn at the current time
};
