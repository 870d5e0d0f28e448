// asp's plan viewer: the model, the assembly sequence step by step, each part flying in along
// its motion. The data (meshes, plan) is the JSON in #asp-data, written by `asp view`.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/OrbitControls.js';

const data = JSON.parse(document.getElementById('asp-data').textContent);
const STEP_SECONDS = 1.2;
const PAUSE_SECONDS = 0.35;
// a grid move (docs/plan-format.md, "Grid plans") takes this fraction of an insertion's time
const MOVE_TIME = 0.5;

function decode(base64, Type) {
  const bin = atob(base64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return new Type(bytes.buffer);
}
const rgb = (c) => new THREE.Color(c[0] / 255, c[1] / 255, c[2] / 255);
const vec = (a) => new THREE.Vector3(a[0], a[1], a[2]);
const css = (c) => `rgb(${c[0]},${c[1]},${c[2]})`;

// --- motions (docs/plan-format.md, "Motions"; the same timing as asp-viz's Insertion::pose_at)
function poseOf(p) {
  return { t: new THREE.Vector3(p[0], p[1], p[2]), q: new THREE.Quaternion(p[3], p[4], p[5], p[6]).normalize() };
}
function apply(pose, point) {
  return point.clone().applyQuaternion(pose.q).add(pose.t);
}
function prepareMotion(m) {
  if (!m || m.kind !== 'path') return m;
  const poses = m.poses.map(poseOf);
  const pivot = vec(m.pivot);
  const weights = [];
  for (let i = 0; i + 1 < poses.length; i++) {
    const travel = apply(poses[i + 1], pivot).distanceTo(apply(poses[i], pivot));
    weights.push(travel + poses[i].q.angleTo(poses[i + 1].q) * m.radius);
  }
  return { ...m, poses, pivotV: pivot, weights, total: weights.reduce((a, b) => a + b, 0) };
}
// The pose {t, q} of a part a fraction s (0 outside, 1 assembled) through its motion.
function poseAt(m, s) {
  s = Math.min(1, Math.max(0, s));
  const identity = { t: new THREE.Vector3(), q: new THREE.Quaternion() };
  if (!m) return identity;
  if (m.kind === 'linear') return { t: vec(m.direction).multiplyScalar(-m.distance * (1 - s)), q: new THREE.Quaternion() };
  const poses = m.poses;
  if (poses.length === 0) return identity;
  if (poses.length === 1 || m.total <= 0) return poses[poses.length - 1];
  let left = s * m.total;
  for (let i = 0; i < m.weights.length; i++) {
    const w = m.weights[i];
    if (left <= w || i + 1 === m.weights.length) {
      const f = w > 0 ? Math.min(1, Math.max(0, left / w)) : 1;
      const a = poses[i], b = poses[i + 1];
      const centre = apply(a, m.pivotV).lerp(apply(b, m.pivotV), f);
      const q = a.q.clone().slerp(b.q, f);
      return { t: centre.sub(m.pivotV.clone().applyQuaternion(q)), q };
    }
    left -= w;
  }
  return poses[poses.length - 1];
}

// --- the scene
const container = document.getElementById('asp-canvas');
const up = vec(data.up);
THREE.Object3D.DEFAULT_UP.copy(up);
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.setClearColor(0xf4f5f7);
container.appendChild(renderer.domElement);
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(35, window.innerWidth / window.innerHeight, 1e-3, 1e6);
camera.up.copy(up);
scene.add(new THREE.HemisphereLight(0xffffff, 0x8090a0, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
camera.add(sun);
sun.position.set(0.4, 1, 0.6);
scene.add(camera);

const parts = data.parts.map((p, i) => {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(decode(p.positions, Float32Array), 3));
  geometry.setIndex(new THREE.BufferAttribute(decode(p.indices, p.index_bits === 16 ? Uint16Array : Uint32Array), 1));
  geometry.computeBoundingBox();
  const colour = rgb(p.colour);
  const material = new THREE.MeshStandardMaterial({ color: colour, flatShading: true, side: THREE.DoubleSide, roughness: 0.75, metalness: 0.0 });
  const mesh = new THREE.Mesh(geometry, material);
  mesh.name = p.name;
  mesh.visible = false;
  scene.add(mesh);
  const centre = new THREE.Vector3();
  geometry.boundingBox.getCenter(centre);
  // `swatch`: the file's sRGB bytes as CSS (`colour` is three's Color, which CSS cannot read)
  return { ...p, index: i, mesh, material, colour, swatch: css(p.colour), centre };
});
const steps = data.steps.map((s) => {
  const moves = (s.moves || []).map((m) => ({ parts: m.parts, t: vec(m.translation) }));
  return { ...s, group: s.group || [s.part], motion: prepareMotion(s.motion), moves, duration: 1 + MOVE_TIME * moves.length };
});

// --- grid moves: the same rules as asp-viz's Scene::offset and Scene::pose_during
// Where part i sits, relative to its assembled pose, once step k went in and `done` of its
// moves are made: minus every later move of it (k = steps.length: the end, in place).
function offset(i, k, done) {
  const d = new THREE.Vector3();
  for (let j = k; j < steps.length; j++) {
    const moves = steps[j].moves;
    for (let m = j === k ? done : 0; m < moves.length; m++) if (moves[m].parts.includes(i)) d.sub(moves[m].t);
  }
  return d;
}
// The pose {t, q} of part i at time u (0 .. duration) of step k: the step's parts follow its
// insertion while u <= 1, then each move slides its parts in turn; the rest stay put.
function partPose(k, u, i) {
  const s = steps[k];
  let done = 0, f = 0;
  if (u > 1) {
    const w = (u - 1) / MOVE_TIME;
    done = Math.min(Math.max(Math.floor(w), 0), s.moves.length);
    f = done < s.moves.length ? Math.min(1, Math.max(0, w - done)) : 0;
  }
  const t = offset(i, k, done);
  if (f > 0 && done < s.moves.length && s.moves[done].parts.includes(i)) t.addScaledVector(s.moves[done].t, f);
  const base = s.group.includes(i) ? poseAt(s.motion, Math.min(u, 1)) : poseAt(null, 1);
  return { t: base.t.clone().add(t), q: base.q };
}

// the bounds of the model and of every motion's start: the camera sees all of it
const bounds = new THREE.Box3();
for (const p of parts) bounds.union(p.mesh.geometry.boundingBox);
for (const s of steps) {
  if (!s.motion) continue;
  for (const i of s.group) {
    const box = parts[i].mesh.geometry.boundingBox;
    for (let k = 0; k <= 8; k++) {
      const pose = partPose(steps.indexOf(s), k / 8, i);
      for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) for (const z of [box.min.z, box.max.z])
        bounds.expandByPoint(apply(pose, new THREE.Vector3(x, y, z)));
    }
  }
}
const centre = bounds.getCenter(new THREE.Vector3());
const radius = Math.max(bounds.getSize(new THREE.Vector3()).length() / 2, 1e-9);

// a grid on the floor under the model, square to the up axis
const grid = new THREE.GridHelper(radius * 3, 12, 0xb8bec8, 0xd6dae0);
grid.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), up);
const modelBox = new THREE.Box3();
for (const p of parts) modelBox.union(p.mesh.geometry.boundingBox);
const lowest = Math.min(...[modelBox.min, modelBox.max].map((c) => c.dot(up)));
grid.position.copy(centre).addScaledVector(up, lowest - centre.dot(up));
scene.add(grid);

// an isometric-ish view: from the side, a little above
const side = Math.abs(up.x) > 0.9 ? new THREE.Vector3(0, 1, 0) : new THREE.Vector3(1, 0, 0);
const other = new THREE.Vector3().crossVectors(up, side);
const viewDir = side.clone().multiplyScalar(1).addScaledVector(other, -0.9).addScaledVector(up, 0.75).normalize();
const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 1.05;
camera.position.copy(centre).addScaledVector(viewDir, distance);
camera.near = distance / 1000;
camera.far = distance * 100;
function frameView() {
  const panel = document.getElementById('asp-panel');
  const left = window.innerWidth > 700 ? panel.offsetLeft + panel.offsetWidth : 0;
  // the full view is wider by the panel; the window shows its right part, so the view's centre
  // sits in the middle of the area right of the panel
  camera.aspect = (window.innerWidth + left) / window.innerHeight;
  camera.setViewOffset(window.innerWidth + left, window.innerHeight, 0, 0, window.innerWidth, window.innerHeight);
  camera.updateProjectionMatrix();
}
frameView();
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.copy(centre);
controls.update();

// the motion of the part in flight, drawn as a line from its start to its place
const pathMaterial = new THREE.LineBasicMaterial({ color: 0xe65100 });
let pathLine = null;
function showPath(k) {
  if (pathLine) { scene.remove(pathLine); pathLine.geometry.dispose(); pathLine = null; }
  const step = k >= 0 ? steps[k] : null;
  if (!step || !step.motion) return;
  const c = parts[step.part].centre;
  const samples = step.motion.kind === 'path' ? 64 : 1;
  const points = [];
  for (let j = 0; j <= samples; j++) points.push(apply(partPose(k, j / samples, step.part), c));
  pathLine = new THREE.Line(new THREE.BufferGeometry().setFromPoints(points), pathMaterial);
  scene.add(pathLine);
}

// --- the sequence
const state = { shown: 0, playing: false, flying: -1, t: 1, wait: 0 };
const initial = new Set(data.initial);
const stuck = new Set(data.stuck);
const label = document.getElementById('asp-label');

function place(part, pose) {
  part.mesh.position.copy(pose.t);
  part.mesh.quaternion.copy(pose.q);
}
function apply_state() {
  const k = state.flying;
  for (const p of parts) {
    p.mesh.visible = initial.has(p.index);
    // in flight: step k's timeline (its insertion, then its moves); at rest: every move of the
    // steps shown is made
    place(p, k >= 0 ? partPose(k, state.t, p.index) : { t: offset(p.index, state.shown, 0), q: new THREE.Quaternion() });
    p.material.emissive.setRGB(0, 0, 0);
  }
  // a step puts in one part, or a whole subassembly (`group`: its parts move together)
  for (let j = 0; j < state.shown; j++) for (const i of steps[j].group) parts[i].mesh.visible = true;
  if (k >= 0) {
    const s = steps[k];
    const moving = state.t <= 1 || !s.moves.length ? s.group : s.moves[Math.min(s.moves.length - 1, Math.floor((state.t - 1) / MOVE_TIME))].parts;
    for (const i of moving) parts[i].material.emissive.setRGB(0.25, 0.18, 0.0);
  }
  const current = state.flying >= 0 ? state.flying : state.shown - 1;
  showPath(current);
  updatePanel(current);
}

function current() { return state.flying >= 0 ? state.flying : state.shown - 1; }
function goto(k) {
  state.shown = Math.max(0, Math.min(steps.length, k | 0));
  state.flying = -1;
  state.t = 1;
  apply_state();
  return api.state();
}
function step() {
  if (state.flying >= 0) { state.flying = -1; state.t = 1; }
  if (state.shown < steps.length) {
    state.shown += 1;
    state.flying = state.shown - 1;
    state.t = 0;
  }
  apply_state();
  return api.state();
}
function back() { return goto(state.shown - 1); }
function play() {
  if (state.shown >= steps.length && state.flying < 0) goto(0);
  state.playing = true;
  state.wait = 0;
  updatePanel(current());
  return api.state();
}
function pause() { state.playing = false; updatePanel(current()); return api.state(); }

// --- the panel
document.getElementById('asp-title').textContent = data.title;
const status = document.getElementById('asp-status');
status.textContent = data.status_text;
if (data.status !== 'found') status.className = 'bad';
const base = document.getElementById('asp-base');
const baseParts = parts.filter((p) => initial.has(p.index));
if (baseParts.length) {
  base.innerHTML = '';
  const head = document.createElement('b');
  head.textContent = (data.status === 'found' || data.status === 'partial') ? 'Base: ' : 'Dead end (the start): ';
  base.appendChild(head);
  baseParts.forEach((p, i) => {
    const s = document.createElement('span');
    s.innerHTML = `<span class="swatch" style="background:${p.swatch}"></span>`;
    s.appendChild(document.createTextNode(p.name + (i + 1 < baseParts.length ? ', ' : '')));
    base.appendChild(s);
  });
} else {
  base.textContent = 'Base: the ground plane';
}
const list = document.getElementById('asp-steps');
const items = steps.map((s, k) => {
  const li = document.createElement('li');
  li.innerHTML = `<span class="swatch" style="background:${parts[s.part].swatch}"></span>`;
  const how = (s.motion ? (s.motion.kind === 'path' ? ' (path)' : '') : '') +
    (s.group.length > 1 ? ` + ${s.group.length - 1} parts (subassembly)` : '');
  li.appendChild(document.createTextNode(s.name + how));
  if (parts[s.part].path) {
    // where the part sits in the file's product tree (STEP subassemblies)
    const tree = document.createElement('span');
    tree.className = 'asp-tree';
    tree.style.opacity = '0.6';
    tree.textContent = ` in ${parts[s.part].path}`;
    li.appendChild(tree);
  }
  li.addEventListener('click', () => { pause(); goto(k + 1); });
  list.appendChild(li);
  return li;
});
const explanation = document.getElementById('asp-explanation');
for (const e of data.explanation) {
  const li = document.createElement('li');
  li.textContent = e.text;
  explanation.appendChild(li);
}
// the precedence graph, when the plan has one: the steps by level (a level's steps may go in
// side by side, once every earlier level is in), the critical path in bold; a click on a step
// shows the model up to it
const precedence = document.getElementById('asp-precedence');
if (data.precedence) {
  const p = data.precedence;
  const critical = new Set(p.critical_path);
  const head = document.createElement('div');
  head.textContent = `Precedence: ${p.levels.length} levels, critical path ${p.critical_path.length} steps` +
    (p.conservative ? ' (support edges conservative)' : '');
  precedence.appendChild(head);
  const levels = document.createElement('ol');
  p.levels.forEach((level) => {
    const li = document.createElement('li');
    li.className = 'asp-level';
    level.forEach((k, j) => {
      const a = document.createElement('span');
      a.className = critical.has(k) ? 'asp-step critical' : 'asp-step';
      if (critical.has(k)) a.style.fontWeight = 'bold';
      a.style.cursor = 'pointer';
      a.textContent = `${k + 1}. ${steps[k] ? steps[k].name : '?'}`;
      a.addEventListener('click', () => { pause(); goto(k + 1); });
      li.appendChild(a);
      if (j + 1 < level.length) li.appendChild(document.createTextNode(' | '));
    });
    levels.appendChild(li);
  });
  precedence.appendChild(levels);
  precedence.hidden = false;
}
const counter = document.getElementById('asp-counter');
const playButton = document.getElementById('asp-play');
function updatePanel(cur) {
  counter.textContent = `Step ${state.shown} / ${steps.length}` + (cur >= 0 ? `: ${steps[cur].name}` : '');
  items.forEach((li, k) => { li.className = k === cur ? 'current' : k < state.shown ? 'done' : 'todo'; });
  playButton.textContent = state.playing ? '\u275A\u275A' : '\u25B6';
  document.getElementById('asp-state').textContent = JSON.stringify(api.state());
}
document.getElementById('asp-reset').addEventListener('click', () => { pause(); goto(0); });
document.getElementById('asp-back').addEventListener('click', () => { pause(); back(); });
document.getElementById('asp-step').addEventListener('click', () => { pause(); step(); });
playButton.addEventListener('click', () => (state.playing ? pause() : play()));
window.addEventListener('keydown', (e) => {
  if (e.key === ' ') { e.preventDefault(); state.playing ? pause() : play(); }
  else if (e.key === 'ArrowRight') { pause(); step(); }
  else if (e.key === 'ArrowLeft') { pause(); back(); }
  else if (e.key === 'Home') { pause(); goto(0); }
});
window.addEventListener('resize', () => {
  renderer.setSize(window.innerWidth, window.innerHeight);
  frameView();
});

// --- the loop
const clock = new THREE.Clock();
const screen = new THREE.Vector3();
function frame() {
  const dt = Math.min(clock.getDelta(), 0.1);
  if (state.flying >= 0) {
    // without a recorded motion the part is placed at once; its moves still play
    const s = steps[state.flying];
    if (!s.motion && state.t < 1) state.t = 1;
    state.t = Math.min(s.duration, state.t + dt / STEP_SECONDS);
    if (state.t >= s.duration) { state.flying = -1; state.t = 1; state.wait = 0; }
    apply_state();
  } else if (state.playing) {
    state.wait += dt;
    if (state.shown >= steps.length) pause();
    else if (state.wait >= PAUSE_SECONDS) step();
  }
  controls.update();
  renderer.render(scene, camera);
  const cur = current();
  if (cur >= 0) {
    const p = parts[steps[cur].part];
    screen.copy(p.centre).applyQuaternion(p.mesh.quaternion).add(p.mesh.position).project(camera);
    label.style.display = screen.z < 1 ? 'block' : 'none';
    label.style.left = `${(screen.x + 1) / 2 * window.innerWidth}px`;
    label.style.top = `${(1 - screen.y) / 2 * window.innerHeight}px`;
    label.textContent = `${cur + 1}. ${steps[cur].name}`;
  } else {
    label.style.display = 'none';
  }
  requestAnimationFrame(frame);
}

const api = {
  ready: false,
  goto, step, back, play, pause,
  reset: () => { pause(); return goto(0); },
  // the pose of step k's part a fraction s through its motion (model units): {t: [x,y,z], q: [x,y,z,w]}
  poseAt: (k, s) => {
    const p = poseAt(steps[k].motion, s);
    return { t: [p.t.x, p.t.y, p.t.z], q: [p.q.x, p.q.y, p.q.z, p.q.w] };
  },
  // the pose of part i at time u of step k's timeline (its insertion, then its grid moves)
  partPose: (k, u, i) => {
    const p = partPose(k, u, i);
    return { t: [p.t.x, p.t.y, p.t.z], q: [p.q.x, p.q.y, p.q.z, p.q.w] };
  },
  state: () => ({
    shown: state.shown,
    total: steps.length,
    status: data.status,
    playing: state.playing,
    flying: state.flying >= 0 ? steps[state.flying].part : null,
    t: state.t,
    current: current() >= 0 ? steps[current()].part : null,
    visible: parts.filter((p) => p.mesh.visible).map((p) => p.index),
    stuck: [...stuck],
  }),
};
window.aspViewer = api;
// a found or partial plan opens assembled (a partial one's locked cores in red); an unfinished one on its dead end, the stuck parts in red
if (data.status === 'found' || data.status === 'partial') state.shown = steps.length;
apply_state();
renderer.render(scene, camera);
api.ready = true;
requestAnimationFrame(frame);
