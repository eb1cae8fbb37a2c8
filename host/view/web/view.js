// Live view of a tissue-host session (`tissue-host run SCENARIO.toml --view`).
// Protocol: host/view/VIEW_PROTOCOL.md. No framework, no build step: three.js comes from the
// host as /three.module.js (import map in index.html) and /OrbitControls.js.
import * as THREE from 'three';
import { OrbitControls } from '/OrbitControls.js';

// ---------------------------------------------------------------------------------------------
// Constants
const FRAME_MAGIC = 0x31465654;     // "TVF1"
const HEADER_BYTES = 96;
const MODES = ['none', 'probe', 'scalpel'];
const KEEPALIVE_MS = 200;           // the host withdraws a silent tool after 500 ms
const RECONNECT_MS = 1000;
const WHEEL_STEP_M = 0.001;         // tool depth per wheel notch (shift: WHEEL_FINE_STEP_M)
const WHEEL_FINE_STEP_M = 0.0002;
const TURN_RAD = THREE.MathUtils.degToRad(15);
const ARROW_M_PER_N = 0.01;         // force arrow: 1 cm per newton
const TOOL_ABOVE_M = 0.02;          // initial/reset tip height above the top of the bounds

const $ = (id) => document.getElementById(id);

// ---------------------------------------------------------------------------------------------
// State exposed for tests and debugging (kept current).
const tv = {
  connected: false,
  hello: null,
  framesReceived: 0,
  framesRendered: 0,
  lastFrameTime: null,        // time_s of the last frame received (session time)
  lastFrameReceivedAt: null,  // performance.now() when it arrived
  lastFrame: null,            // header of the last frame (tip, handle, force, ...)
  lastStats: null,
  statsReceived: 0,
  posesSent: 0,
  fps: 0,
  applyMsTotal: 0,    // time spent applying frames (mapping the points, normals) and rendering, summed
  renderMsTotal: 0,
  webgl: false,
  error: null,
};
window.tissueView = tv;

let bounds = { lower: new THREE.Vector3(-0.05, -0.05, 0), upper: new THREE.Vector3(0.05, 0.05, 0.05) };
let controlsEnabled = false;   // hello.controls
let deviceMaxForce = 0;        // hello.device_max_force_n, updated from frames
let bladeLength = 0.1;         // hello.blade_length_m
let unit = 0.001;              // size of small markers, scaled to the bounds on hello
let fittedFor = null;          // bounds the camera was last fitted to (refit only when they change)

// The tool as this page commands it (the "device").
const tool = {
  position: new THREE.Vector3(),
  orientation: new THREE.Quaternion(),  // identity: tool axis +z, handle above the tip
  mode: 'none',
};
let seq = 0;                   // never reset, so it also increases across reconnects
let poseDirty = false;
let lastPoseSentAt = 0;
let lastPoseText = '';

// ---------------------------------------------------------------------------------------------
// Scene
const container = $('view');
let renderer = null;
try {
  renderer = new THREE.WebGLRenderer({ antialias: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(window.innerWidth, window.innerHeight);
  container.appendChild(renderer.domElement);
  tv.webgl = true;
} catch (err) {
  tv.error = 'WebGL unavailable: ' + err.message;
  container.textContent = tv.error;
}
const canvas = renderer ? renderer.domElement : container;

const scene = new THREE.Scene();
scene.background = new THREE.Color(0x1b1e24);
const camera = new THREE.PerspectiveCamera(40, window.innerWidth / window.innerHeight, 0.001, 100);
camera.up.set(0, 0, 1);        // z is up: gravity is -z
camera.position.set(0.3, 0, 0.2);
scene.add(camera);
scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 1.2));
const headLight = new THREE.DirectionalLight(0xffffff, 1.6);
headLight.position.set(0.3, 0.5, 1);   // relative to the camera: above and to the right
camera.add(headLight);

const orbit = new OrbitControls(camera, canvas);
orbit.enableDamping = false;

// The surface: one geometry, two index groups (mesh triangles, then cut faces).
const surfaceGeometry = new THREE.BufferGeometry();
const surfaceMaterials = [
  new THREE.MeshStandardMaterial({ color: 0xe8a0a0, roughness: 0.65, side: THREE.DoubleSide }),  // tissue
  new THREE.MeshStandardMaterial({ color: 0x7a0c12, roughness: 0.5, side: THREE.DoubleSide }),   // cut faces
];
const surface = new THREE.Mesh(surfaceGeometry, surfaceMaterials);
surface.frustumCulled = false;  // the bounding sphere changes every frame
surface.visible = false;
scene.add(surface);
let triangleMaxIndex = -1;      // largest vertex index of the triangles held (-1: none yet)

const grid = new THREE.GridHelper(1, 10, 0x555a66, 0x33363e);
grid.rotation.x = Math.PI / 2;  // GridHelper lies in x-z; the floor here is x-y
scene.add(grid);

// Tool as the engine reports it (from frames). Unit-sized parts scaled per frame.
const probeMaterial = new THREE.MeshStandardMaterial({ color: 0x9e9e9e, metalness: 0.3, roughness: 0.4 });
const bladeMaterial = new THREE.MeshStandardMaterial({ color: 0xc9d6e3, metalness: 0.3, roughness: 0.3, side: THREE.DoubleSide });
const probeRod = new THREE.Mesh(new THREE.CylinderGeometry(1, 1, 1, 12), probeMaterial);  // axis +y
const probeTip = new THREE.Mesh(new THREE.SphereGeometry(1, 16, 12), probeMaterial);
const blade = new THREE.Mesh(new THREE.BoxGeometry(1, 1, 1), bladeMaterial);  // length along +y
const contactMarker = new THREE.Mesh(new THREE.SphereGeometry(1, 16, 12),
  new THREE.MeshBasicMaterial({ color: 0xffeb3b }));
const forceArrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 0.01, 0xffa726);
// The commanded pose (what this page sends), drawn faintly when the page has the controls.
const ghostMaterial = new THREE.LineBasicMaterial({ color: 0x80deea, transparent: true, opacity: 0.6 });
const ghostLine = new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3(0, 0, 1)]), ghostMaterial);
const ghostTip = new THREE.Mesh(new THREE.SphereGeometry(1, 12, 8),
  new THREE.MeshBasicMaterial({ color: 0x80deea, wireframe: true }));
for (const o of [probeRod, probeTip, blade, contactMarker, forceArrow, ghostLine, ghostTip]) {
  o.visible = false;
  o.frustumCulled = false;
  scene.add(o);
}
// The force arrow and the commanded tip show through the tissue: the tip is often inside it.
for (const o of [forceArrow.line, forceArrow.cone, ghostLine, ghostTip]) {
  o.material.depthTest = false;
  o.renderOrder = 10;
}

// ---------------------------------------------------------------------------------------------
// WebSocket
let socket = null;

function socketUrl() {
  const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
  // Pass the page's token on exactly as written in the address (no re-encoding).
  const m = /[?&]token=([^&#]*)/.exec(location.search);
  return `${scheme}://${location.host}/ws` + (m ? `?token=${m[1]}` : '');
}

function connect() {
  setConnState('connecting…', false);
  let ws;
  try {
    ws = new WebSocket(socketUrl());
  } catch (err) {
    setConnState('cannot connect: ' + err.message, false);
    setTimeout(connect, RECONNECT_MS);
    return;
  }
  ws.binaryType = 'arraybuffer';
  socket = ws;
  ws.onopen = () => { tv.connected = true; setConnState('connected', true); };
  ws.onclose = () => {
    tv.connected = false;
    if (socket === ws) socket = null;
    setConnState('disconnected, retrying…', false);
    setTimeout(connect, RECONNECT_MS);
  };
  ws.onmessage = (ev) => {
    if (typeof ev.data === 'string') {
      let msg;
      try { msg = JSON.parse(ev.data); } catch { return; }
      if (msg && msg.type === 'hello') onHello(msg);
      else if (msg && msg.type === 'stats') onStats(msg);
    } else if (ev.data instanceof ArrayBuffer) {
      onFrame(ev.data);
    }
  };
}

function setConnState(text, ok) {
  const el = $('conn');
  el.textContent = text;
  el.className = ok ? 'state-connected' : 'state-disconnected';
}

// ---------------------------------------------------------------------------------------------
// hello
function vec3(a, fallback) {
  return Array.isArray(a) && a.length === 3 && a.every(Number.isFinite) ? new THREE.Vector3(...a) : fallback;
}

function onHello(msg) {
  tv.hello = msg;
  const b = msg.bounds || {};
  bounds = { lower: vec3(b.lower, bounds.lower), upper: vec3(b.upper, bounds.upper) };
  controlsEnabled = msg.controls === true;
  if (Number.isFinite(msg.device_max_force_n)) deviceMaxForce = msg.device_max_force_n;
  if (Number.isFinite(msg.blade_length_m) && msg.blade_length_m > 0) bladeLength = msg.blade_length_m;
  const diag = bounds.upper.distanceTo(bounds.lower) || 0.1;
  unit = Math.max(diag * 0.01, 0.0002);

  const key = JSON.stringify([bounds.lower.toArray(), bounds.upper.toArray()]);
  if (fittedFor !== key) {   // first hello, or another scenario: fit the camera, reset the tool
    fittedFor = key;
    fitCamera();
    resetTool();
    poseDirty = false;       // do not send a pose before the user does anything
  }
  configureInput();
  $('role').textContent = (msg.scenario ? `scenario ${msg.scenario} · ` : '') +
    (controlsEnabled ? 'mouse & keyboard drive the tool' : 'watching only');
  $('role').className = controlsEnabled ? '' : 'watching';
}

function fitCamera() {
  const center = bounds.lower.clone().add(bounds.upper).multiplyScalar(0.5);
  const radius = Math.max(bounds.upper.distanceTo(bounds.lower) / 2, 0.01);
  const dist = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 1.15;
  // Look from +x and above: the view direction has no y component, so screen-right is +y.
  const dir = new THREE.Vector3(0.75, 0, 0.66).normalize();
  camera.position.copy(center).addScaledVector(dir, dist);
  camera.near = dist / 100;
  camera.far = dist * 100;
  camera.updateProjectionMatrix();
  orbit.target.copy(center);
  orbit.update();
  // A 10-line floor grid under the body, a little larger than it.
  const size = radius * 3;
  grid.scale.setScalar(size);
  grid.position.set(center.x, center.y, bounds.lower.z);
}

function configureInput() {
  // With the controls, the left button and the wheel belong to the tool; orbit with the right
  // button, zoom with ctrl+wheel or +/-. Watching only: the usual orbit controls.
  orbit.mouseButtons = controlsEnabled
    ? { LEFT: null, MIDDLE: THREE.MOUSE.PAN, RIGHT: THREE.MOUSE.ROTATE }
    : { LEFT: THREE.MOUSE.ROTATE, MIDDLE: THREE.MOUSE.PAN, RIGHT: THREE.MOUSE.ROTATE };
  orbit.enableZoom = !controlsEnabled;
  $('help').textContent = controlsEnabled
    ? 'left drag: move the tip across the view · wheel: depth (shift: fine)\n' +
      'right drag: orbit · ctrl+wheel or +/-: zoom\n' +
      '0/n none · 1/p probe · 2/s scalpel · q/e turn ±15° · r reset'
    : 'watching only · drag: orbit · wheel: zoom';
}

// ---------------------------------------------------------------------------------------------
// stats
function onStats(s) {
  tv.lastStats = s;
  tv.statsReceived++;
  const f = (v, d = 0) => (Number.isFinite(v) ? v.toFixed(d) : '–');
  const hp = s.haptic_period_us || {};
  const ts = s.tissue_step_ms || {};
  const m = s.messages || {};
  const dropped = ['malformed', 'oversized', 'flood', 'out_of_order']
    .reduce((sum, k) => sum + (Number.isFinite(m[k]) ? m[k] : 0), 0);
  $('stats').textContent =
    `sim time         ${f(s.sim_time_s, 2)} s\n` +
    `realtime factor  ${f(s.realtime_factor, 2)}\n` +
    `haptic period    ${f(hp.p50)} / ${f(hp.p99)} / ${f(hp.max)} us (p50/p99/max)\n` +
    `deadline misses  ${f(s.deadline_misses)}\n` +
    `tissue step      ${f(ts.p50, 2)} / ${f(ts.p99, 2)} ms (p50/p99)\n` +
    `cut tets         ${f(s.cut_tets)}\n` +
    `viewers          ${f(s.viewers)}\n` +
    `frames skipped   ${f(s.frames_skipped)} of ${f(s.frames_sent)} sent\n` +
    `messages dropped ${dropped} of ${f(m.received)}\n` +
    `  malformed ${f(m.malformed)} · oversized ${f(m.oversized)}\n` +
    `  flood ${f(m.flood)} · out of order ${f(m.out_of_order)}\n` +
    `render           ${tv.fps} fps`;
}

// ---------------------------------------------------------------------------------------------
// frame: parsed on arrival, applied to the scene in the next animation frame (only the latest).
let pendingFrame = null;       // { header, positions: Float32Array } (a mapped frame's: the nodes)
let pendingTriangles = null;   // { triangles: Uint32Array, meshCount, revision, embedding }
// A mapped surface (flag 2): each point at sum_k weight[4i+k] * node[pointNodes[4i+k]]; the
// embedding comes with the triangles, the nodes with every frame (VIEW_PROTOCOL.md).
let embedding = null;          // { pointNodes: Uint32Array, weights: Float32Array, nodeCount } or null
let mappedPositions = new Float32Array(0);

// The points of a mapped frame at its nodes (null if the nodes are not the embedding's).
function mapPoints(nodes) {
  if (!embedding || nodes.length !== 3 * embedding.nodeCount) return null;
  const { pointNodes, weights } = embedding;
  const points = weights.length / 4;
  if (mappedPositions.length < 3 * points) mappedPositions = new Float32Array(3 * points);
  const out = mappedPositions;
  for (let i = 0; i < points; i++) {
    let x = 0, y = 0, z = 0;
    for (let k = 4 * i; k < 4 * i + 4; k++) {
      const w = weights[k], n = 3 * pointNodes[k];
      x += w * nodes[n]; y += w * nodes[n + 1]; z += w * nodes[n + 2];
    }
    out[3 * i] = x; out[3 * i + 1] = y; out[3 * i + 2] = z;
  }
  return out.subarray(0, 3 * points);
}

function onFrame(buf) {
  if (buf.byteLength < HEADER_BYTES) return;
  const dv = new DataView(buf);
  if (dv.getUint32(0, true) !== FRAME_MAGIC) return;
  const flags = dv.getUint32(4, true);
  const V = dv.getUint32(8, true);
  const T = dv.getUint32(12, true);
  const M = dv.getUint32(16, true);
  const hasTriangles = (flags & 1) !== 0;
  const mapped = (flags & 2) !== 0;
  const P = mapped ? dv.getUint32(92, true) : 0;   // a mapped frame's points (V are its nodes)
  const need = HEADER_BYTES + 12 * V + (hasTriangles ? 32 * P + 12 * T : 0);
  if (buf.byteLength < need || M > T) return;   // malformed: ignore
  const f3 = (o) => [dv.getFloat32(o, true), dv.getFloat32(o + 4, true), dv.getFloat32(o + 8, true)];
  const header = {
    flags, mapped, vertexCount: mapped ? P : V, nodeCount: V, triangleCount: T, meshTriangleCount: M,
    topologyRevision: dv.getUint32(20, true),
    time: dv.getFloat64(24, true),
    tip: f3(32), handle: f3(44),
    mode: dv.getUint32(56, true), contact: dv.getUint32(60, true) !== 0,
    contactPoint: f3(64), force: f3(76), maxForce: dv.getFloat32(88, true),
  };
  // binaryType 'arraybuffer' gives a fresh buffer per message, so these views stay valid.
  const positions = new Float32Array(buf, HEADER_BYTES, 3 * V);
  if (hasTriangles) {
    let at = HEADER_BYTES + 12 * V;
    let frameEmbedding = null;
    if (mapped) {
      frameEmbedding = { pointNodes: new Uint32Array(buf, at, 4 * P), weights: new Float32Array(buf, at + 16 * P, 4 * P),
                         nodeCount: V };
      at += 32 * P;
    }
    pendingTriangles = { triangles: new Uint32Array(buf, at, 3 * T), meshCount: M,
                         revision: header.topologyRevision, embedding: frameEmbedding };
  }
  pendingFrame = { header, positions };
  tv.framesReceived++;
  tv.lastFrameTime = header.time;
  tv.lastFrameReceivedAt = performance.now();
  tv.lastFrame = header;
  if (header.maxForce > 0) deviceMaxForce = header.maxForce;
}

// GPU buffers are reused while they are large enough (while a cut runs, the sizes change every
// frame); when one must grow, all of the geometry's buffers are released (dispose) and rebuilt,
// so cutting does not leak GPU memory.
const capacityFor = (n) => Math.max(1024, 2 ** Math.ceil(Math.log2(n)));

// Area-weighted vertex normals over typed arrays (three.js' computeVertexNormals goes through
// Vector3 objects: 5 ms a frame for the frog's fine surface in the page, this about a tenth).
function vertexNormals(positions, index, normal) {
  const n = normal.array, p = positions, idx = index.array;
  n.fill(0);
  for (let t = 0; t < idx.length; t += 3) {
    const a = 3 * idx[t], b = 3 * idx[t + 1], c = 3 * idx[t + 2];
    if (a === b) continue;   // the unused tail: degenerate
    const ux = p[b] - p[a], uy = p[b + 1] - p[a + 1], uz = p[b + 2] - p[a + 2];
    const vx = p[c] - p[a], vy = p[c + 1] - p[a + 1], vz = p[c + 2] - p[a + 2];
    const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    n[a] += nx; n[a + 1] += ny; n[a + 2] += nz;
    n[b] += nx; n[b + 1] += ny; n[b + 2] += nz;
    n[c] += nx; n[c + 1] += ny; n[c + 2] += nz;
  }
  for (let v = 0; v < p.length; v += 3) {
    const len = Math.hypot(n[v], n[v + 1], n[v + 2]);
    if (len > 0) { n[v] /= len; n[v + 1] /= len; n[v + 2] /= len; }
  }
  normal.needsUpdate = true;
}

function applyFrame() {
  if (pendingTriangles) {
    const { triangles, meshCount } = pendingTriangles;
    embedding = pendingTriangles.embedding;
    pendingTriangles = null;
    let max = -1;
    for (let i = 0; i < triangles.length; i++) if (triangles[i] > max) max = triangles[i];
    triangleMaxIndex = max;
    let index = surfaceGeometry.getIndex();
    if (!index || index.array.length < triangles.length) {
      surfaceGeometry.dispose();
      index = new THREE.BufferAttribute(new Uint32Array(3 * capacityFor(triangles.length / 3)), 1);
      index.setUsage(THREE.DynamicDrawUsage);
      surfaceGeometry.setIndex(index);
    }
    index.array.set(triangles);
    index.array.fill(0, triangles.length);   // unused tail: degenerate triangles, no normals
    index.needsUpdate = true;
    // The groups say what is drawn: mesh triangles with material 0, cut faces with material 1.
    surfaceGeometry.clearGroups();
    surfaceGeometry.addGroup(0, 3 * meshCount, 0);
    surfaceGeometry.addGroup(3 * meshCount, triangles.length - 3 * meshCount, 1);
  }
  if (!pendingFrame) return;
  const { header } = pendingFrame;
  const positions = header.mapped ? mapPoints(pendingFrame.positions) : pendingFrame.positions;
  pendingFrame = null;
  if (!positions) {   // nodes of an embedding not held yet: the surface waits for the next topology
    updateToolVisuals(header);
    return;
  }

  let attr = surfaceGeometry.getAttribute('position');
  if (!attr || attr.array.length < positions.length) {
    surfaceGeometry.dispose();
    attr = new THREE.BufferAttribute(new Float32Array(3 * capacityFor(positions.length / 3)), 3);
    attr.setUsage(THREE.DynamicDrawUsage);
    surfaceGeometry.setAttribute('position', attr);
    const normal = new THREE.BufferAttribute(new Float32Array(attr.array.length), 3);
    normal.setUsage(THREE.DynamicDrawUsage);
    surfaceGeometry.setAttribute('normal', normal);
  }
  attr.array.set(positions);
  attr.needsUpdate = true;
  // Draw only when the triangles held refer to vertices that exist.
  surface.visible = triangleMaxIndex >= 0 && triangleMaxIndex < header.vertexCount;
  if (surface.visible) vertexNormals(positions, surfaceGeometry.getIndex(), surfaceGeometry.getAttribute('normal'));

  updateToolVisuals(header);
}

const _a = new THREE.Vector3(), _b = new THREE.Vector3(), _c = new THREE.Vector3();
const _m = new THREE.Matrix4();
const Y = new THREE.Vector3(0, 1, 0);

function updateToolVisuals(h) {
  const tip = _a.fromArray(h.tip), handle = _b.fromArray(h.handle);
  const axis = handle.clone().sub(tip);
  const len = axis.length();
  const mode = MODES[h.mode] || 'none';
  probeRod.visible = probeTip.visible = mode === 'probe' && len > 0;
  blade.visible = mode === 'scalpel' && len > 0;
  if (len > 0) {
    axis.divideScalar(len);
    const mid = tip.clone().add(handle).multiplyScalar(0.5);
    if (probeRod.visible) {
      probeRod.position.copy(mid);
      probeRod.quaternion.setFromUnitVectors(Y, axis);
      probeRod.scale.set(0.5 * unit, len, 0.5 * unit);
      probeTip.position.copy(tip);
      probeTip.scale.setScalar(1.2 * unit);
    }
    if (blade.visible) {
      // A flat strip along the axis, its flat side turned towards the camera.
      const n = _c.copy(camera.position).sub(mid);
      n.addScaledVector(axis, -n.dot(axis));
      if (n.lengthSq() < 1e-12) n.set(1, 0, 0).addScaledVector(axis, -axis.x);
      n.normalize();
      const x = axis.clone().cross(n);
      _m.makeBasis(x, axis, n);
      blade.quaternion.setFromRotationMatrix(_m);
      blade.position.copy(mid);
      blade.scale.set(3 * unit, len, 0.2 * unit);
    }
  }
  contactMarker.visible = h.contact;
  if (h.contact) {
    contactMarker.position.fromArray(h.contactPoint);
    contactMarker.scale.setScalar(0.9 * unit);
  }
  const force = new THREE.Vector3().fromArray(h.force);
  const fmag = force.length();
  forceArrow.visible = fmag > 1e-4 && mode !== 'none';
  if (forceArrow.visible) {
    const alen = fmag * ARROW_M_PER_N;
    forceArrow.position.copy(tip);
    forceArrow.setDirection(force.divideScalar(fmag));
    forceArrow.setLength(alen, Math.min(0.3 * alen, 4 * unit), Math.min(0.2 * alen, 2.5 * unit));
  }
  // HTML force bar against the device's maximum.
  const frac = deviceMaxForce > 0 ? fmag / deviceMaxForce : 0;
  $('forcefill').style.width = `${Math.min(frac, 1) * 100}%`;
  $('forcefill').className = frac > 0.9 ? 'high' : '';
  $('forcetext').textContent = `force on the hand ${fmag.toFixed(2)} N (max ${deviceMaxForce.toFixed(1)} N)\n` +
    `(${h.force.map((v) => v.toFixed(2)).join(', ')}) N · ${mode}${h.contact ? ' · contact' : ''}`;
}

// ---------------------------------------------------------------------------------------------
// The page as a device: pose messages.
function resetTool() {
  const c = bounds.lower.clone().add(bounds.upper).multiplyScalar(0.5);
  tool.position.set(c.x, c.y, bounds.upper.z + TOOL_ABOVE_M);
  tool.orientation.identity();
  poseDirty = true;
}

function setMode(mode) {
  if (!MODES.includes(mode) || mode === tool.mode) return;
  tool.mode = mode;
  poseDirty = true;
}

function sendPose(now) {
  if (!controlsEnabled || !socket || socket.readyState !== WebSocket.OPEN) return false;
  const p = tool.position, q = tool.orientation;
  if (![p.x, p.y, p.z].every(Number.isFinite)) return false;
  const msg = {
    type: 'pose', seq: ++seq,
    position_m: [p.x, p.y, p.z],
    orientation_wxyz: [q.w, q.x, q.y, q.z],
    mode: tool.mode,
  };
  socket.send(JSON.stringify(msg));
  tv.posesSent++;
  lastPoseSentAt = now;
  lastPoseText = `pose #${msg.seq} ${tool.mode} tip (${[p.x, p.y, p.z].map((v) => (v * 1000).toFixed(1)).join(', ')}) mm`;
  return true;
}

// Keep-alive: the host withdraws a tool that has been silent for 0.5 s. A timer rather than the
// render loop, so a slow renderer cannot starve it.
setInterval(() => {
  const now = performance.now();
  if (tool.mode !== 'none' && now - lastPoseSentAt >= KEEPALIVE_MS - 25) sendPose(now);
}, 25);

// ---------------------------------------------------------------------------------------------
// Mouse and keyboard
const pointer = new THREE.Vector2();
const raycaster = new THREE.Raycaster();
let drag = null;   // { pointerId, plane, offset }

function viewDirection() {
  return camera.getWorldDirection(new THREE.Vector3());
}

function pointOnPlane(ev, plane) {
  const rect = canvas.getBoundingClientRect();
  pointer.set(((ev.clientX - rect.left) / rect.width) * 2 - 1, -((ev.clientY - rect.top) / rect.height) * 2 + 1);
  raycaster.setFromCamera(pointer, camera);
  return raycaster.ray.intersectPlane(plane, new THREE.Vector3());
}

canvas.addEventListener('pointerdown', (ev) => {
  if (!controlsEnabled || ev.button !== 0) return;
  // The plane through the current tip, perpendicular to the view direction. The tip keeps its
  // offset from the pointer, so grabbing anywhere does not make it jump.
  const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(viewDirection(), tool.position);
  const hit = pointOnPlane(ev, plane);
  if (!hit) return;
  drag = { pointerId: ev.pointerId, plane, offset: tool.position.clone().sub(hit) };
  canvas.setPointerCapture(ev.pointerId);
  ev.preventDefault();
});

canvas.addEventListener('pointermove', (ev) => {
  if (!drag || ev.pointerId !== drag.pointerId) return;
  const hit = pointOnPlane(ev, drag.plane);
  if (!hit) return;
  tool.position.copy(hit).add(drag.offset);
  poseDirty = true;
});

const endDrag = (ev) => { if (drag && ev.pointerId === drag.pointerId) drag = null; };
canvas.addEventListener('pointerup', endDrag);
canvas.addEventListener('pointercancel', endDrag);

function zoom(factor) {
  // Move the camera towards (factor < 1) or away from the orbit target.
  const offset = camera.position.clone().sub(orbit.target).multiplyScalar(factor);
  camera.position.copy(orbit.target).add(offset);
  orbit.update();
}

canvas.addEventListener('wheel', (ev) => {
  if (!controlsEnabled) return;        // OrbitControls zooms
  ev.preventDefault();
  // Chromium turns shift+wheel into a horizontal scroll: take whichever delta is set.
  const delta = ev.deltaY || ev.deltaX;
  if (!delta) return;
  if (ev.ctrlKey) { zoom(delta > 0 ? 1.1 : 1 / 1.1); return; }
  // One step per wheel event; wheel away from you pushes the tip into the scene.
  const step = (ev.shiftKey ? WHEEL_FINE_STEP_M : WHEEL_STEP_M) * (delta < 0 ? 1 : -1);
  tool.position.addScaledVector(viewDirection(), step);
  poseDirty = true;
}, { passive: false });

window.addEventListener('keydown', (ev) => {
  if (ev.ctrlKey || ev.metaKey || ev.altKey) return;
  const k = ev.key.toLowerCase();
  if (k === '+' || k === '=') { zoom(1 / 1.15); return; }
  if (k === '-' || k === '_') { zoom(1.15); return; }
  if (!controlsEnabled) return;
  if (k === '0' || k === 'n') setMode('none');
  else if (k === '1' || k === 'p') setMode('probe');
  else if (k === '2' || k === 's') setMode('scalpel');
  else if (k === 'q' || k === 'e') {
    // Turn the tool about the view direction (on screen: counter-clockwise for q).
    const turn = new THREE.Quaternion().setFromAxisAngle(viewDirection(), k === 'q' ? -TURN_RAD : TURN_RAD);
    tool.orientation.premultiply(turn).normalize();
    poseDirty = true;
  } else if (k === 'r') resetTool();
  else return;
  ev.preventDefault();
});

window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  if (renderer) renderer.setSize(window.innerWidth, window.innerHeight);
});

// ---------------------------------------------------------------------------------------------
// Test helpers
tv.setTool = (position_m, mode, orientation_wxyz) => {
  if (Array.isArray(position_m) && position_m.length === 3 && position_m.every(Number.isFinite)) {
    tool.position.fromArray(position_m);
  }
  if (Array.isArray(orientation_wxyz) && orientation_wxyz.length === 4 && orientation_wxyz.every(Number.isFinite)) {
    const [w, x, y, z] = orientation_wxyz;
    tool.orientation.set(x, y, z, w).normalize();
  }
  if (mode !== undefined) setMode(mode);
  poseDirty = true;
  return tv.getTool();
};
tv.getTool = () => ({
  position_m: tool.position.toArray(),
  orientation_wxyz: [tool.orientation.w, tool.orientation.x, tool.orientation.y, tool.orientation.z],
  mode: tool.mode,
});
// Client (CSS pixel) coordinates of a world point, seen with the page's camera.
tv.screenOf = (p) => {
  const v = new THREE.Vector3().fromArray(p).project(camera);
  const rect = canvas.getBoundingClientRect();
  return { x: rect.left + (v.x + 1) / 2 * rect.width, y: rect.top + (1 - v.y) / 2 * rect.height };
};

// ---------------------------------------------------------------------------------------------
// Render loop: at the display rate, independent of the socket.
const renderTimes = [];

function updateGhost() {
  const show = controlsEnabled;
  ghostLine.visible = ghostTip.visible = show;
  if (!show) return;
  const axis = new THREE.Vector3(0, 0, 1).applyQuaternion(tool.orientation);
  const handle = tool.position.clone().addScaledVector(axis, bladeLength);
  const pos = ghostLine.geometry.getAttribute('position');
  pos.setXYZ(0, tool.position.x, tool.position.y, tool.position.z);
  pos.setXYZ(1, handle.x, handle.y, handle.z);
  pos.needsUpdate = true;
  ghostTip.position.copy(tool.position);
  ghostTip.scale.setScalar(0.8 * unit);
}

function animate(now) {
  requestAnimationFrame(animate);
  if (poseDirty && sendPose(now)) poseDirty = false;   // at most one pose per animation frame
  const t0 = performance.now();
  applyFrame();
  const t1 = performance.now();
  updateGhost();
  orbit.update();
  if (renderer) renderer.render(scene, camera);
  tv.applyMsTotal += t1 - t0;   // the frame's surface: mapping, upload, normals
  tv.renderMsTotal += performance.now() - t1;
  tv.framesRendered++;
  renderTimes.push(now);
  while (renderTimes.length && renderTimes[0] <= now - 1000) renderTimes.shift();
  tv.fps = renderTimes.length;
  $('pose').textContent = controlsEnabled ? (lastPoseText || `tool ${tool.mode}, no pose sent yet`) : '';
}

fitCamera();        // to the default bounds until hello brings the real ones
configureInput();
connect();
requestAnimationFrame(animate);
