// The page of `arc view`: draws the scene of the JSON block #arc-data with three.js
// (inlined in #three-src, loaded through a blob URL so the page needs no server).
// Every position is computed by `arc`; this script only places and colours things.
const THREE = await import(URL.createObjectURL(new Blob(
  [document.getElementById('three-src').textContent], { type: 'text/javascript' })));
const D = JSON.parse(document.getElementById('arc-data').textContent);
const N = D.units;
const W = D.waypoints;
const F = D.flight;

// Colour of each waypoint class (scene.rs, kind_of), and its legend text.
const KINDS = {
  start: [0x546e7a, 'start'],
  translate: [0x5c6b80, 'translation'],
  library: [0x2e7d32, 'shape change: library (LSC)'],
  srs: [0x7b1fa2, 'shape change: SRS (random)'],
  rotation: [0x0277bd, 'shape change: rotation (yaw)'],
  follow: [0xef6c00, 'shape change: follow the leader'],
  shrunk: [0xc62828, 'shape change: shrunk'],
  sampled: [0xad1457, 'shape change: sampled'],
  other: [0x795548, 'other'],
};
const ROUTE = 0x1565c0, FLOWN = 0xff8f00, GOAL = 0x43a047, OCC = 0xb8c2cf, UNK = 0xc9b48a, SEEN = 0x5d7186;
const S = D.seen;

const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.localClippingEnabled = true;
document.body.prepend(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0xeef1f5);
scene.add(new THREE.HemisphereLight(0xffffff, 0x7a8699, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 2.2);
sun.position.set(0.4, -0.7, 1.0);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(40, window.innerWidth / window.innerHeight, 0.02, 20000);
camera.up.set(0, 0, 1);

const v3 = (a, i) => new THREE.Vector3(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
const Y = new THREE.Vector3(0, 1, 0);
const tmp = new THREE.Object3D();

// Cylinders from p[2k] to p[2k+1]: the links, the route, the flown trail.
function sticks(count, radius, material) {
  const m = new THREE.InstancedMesh(new THREE.CylinderGeometry(radius, radius, 1, 10), material, count);
  m.setPoints = (pairs) => {
    pairs.forEach(([a, b], k) => {
      const d = new THREE.Vector3().subVectors(b, a);
      tmp.position.copy(a).addScaledVector(d, 0.5);
      tmp.quaternion.setFromUnitVectors(Y, d.length() > 1e-9 ? d.clone().normalize() : Y);
      tmp.scale.set(1, Math.max(d.length(), 1e-6), 1);
      tmp.updateMatrix();
      m.setMatrixAt(k, tmp.matrix);
    });
    m.count = pairs.length;
    m.instanceMatrix.needsUpdate = true;
  };
  return m;
}
function balls(count, radius, material) {
  const m = new THREE.InstancedMesh(new THREE.SphereGeometry(radius, 24, 16), material, count);
  m.setPoints = (ps) => {
    ps.forEach((p, k) => { tmp.position.copy(p); tmp.quaternion.identity(); tmp.scale.set(1, 1, 1); tmp.updateMatrix(); m.setMatrixAt(k, tmp.matrix); });
    m.count = ps.length;
    m.instanceMatrix.needsUpdate = true;
  };
  return m;
}

// Obstacles, cut above a height the user picks (so the route stays visible).
const cut = new THREE.Plane(new THREE.Vector3(0, 0, -1), 1e9);
function boxes(idx, color, opacity, at = D.boxes, grow = 1) {
  const n = idx.length / 3;
  if (n === 0) return null;
  const s = at.size, o = at.origin;
  const mat = new THREE.MeshLambertMaterial({ color, clippingPlanes: [cut], transparent: opacity < 1, opacity, depthWrite: opacity >= 1 });
  const m = new THREE.InstancedMesh(new THREE.BoxGeometry(s * grow, s * grow, s * grow), mat, n);
  for (let k = 0; k < n; k++) {
    tmp.position.set(o[0] + s * idx[3 * k], o[1] + s * idx[3 * k + 1], o[2] + s * idx[3 * k + 2]);
    tmp.quaternion.identity(); tmp.scale.set(1, 1, 1); tmp.updateMatrix();
    m.setMatrixAt(k, tmp.matrix);
  }
  scene.add(m);
  return m;
}
// With an exploration's map the world turns faint and the boxes its sensors saw
// appear in the order they were seen (S.t ascending: the first `count` are drawn).
boxes(D.boxes.occupied, OCC, S ? 0.16 : 1);
boxes(D.boxes.unknown, UNK, S ? 0.1 : 0.35);
// (a hair larger than the world's, so that the faint box does not fight the seen one)
const seenMesh = S ? boxes(S.boxes, SEEN, 1, S, 1.01) : null;

// The head route and the shape-change waypoints on it, coloured by source; on a long
// route the trails thicken so they stay visible when the whole route is framed.
const wn = W.t.length;
const heads = [...Array(wn).keys()].map((i) => v3(W.units, i * N));
const span = new THREE.Box3().setFromPoints(heads).getSize(new THREE.Vector3()).length();
const trailRadius = Math.max(D.link_radius, D.unit_radius * 0.12, span * 0.0012);
const route = sticks(Math.max(wn - 1, 1), trailRadius, new THREE.MeshLambertMaterial({ color: ROUTE }));
route.setPoints(heads.slice(1).map((h, i) => [heads[i], h]));
scene.add(route);
const marks = [...Array(wn).keys()].filter((i) => !['translate', 'start'].includes(W.kind[i]));
if (marks.length) {
  const m = balls(marks.length, D.unit_radius * 0.35, new THREE.MeshLambertMaterial({ color: 0xffffff }));
  m.setPoints(marks.map((i) => heads[i]));
  marks.forEach((i, k) => m.setColorAt(k, new THREE.Color(KINDS[W.kind[i]][0])));
  scene.add(m);
}

// The goal region.
if (D.goal) {
  const g = new THREE.Mesh(new THREE.SphereGeometry(D.goal.radius, 32, 16),
    new THREE.MeshLambertMaterial({ color: GOAL, transparent: true, opacity: 0.3, depthWrite: false }));
  g.position.fromArray(D.goal.center);
  scene.add(g);
  const w = new THREE.LineSegments(new THREE.WireframeGeometry(g.geometry), new THREE.LineBasicMaterial({ color: GOAL }));
  w.position.copy(g.position);
  scene.add(w);
}

// The planned chain at the current waypoint: units as spheres of r_u, links as cylinders.
// With a flight the planned units turn translucent, so the flown ones show inside them.
const unitMat = new THREE.MeshStandardMaterial({ color: 0xffffff, roughness: 0.5, transparent: !!F, opacity: F ? 0.45 : 1, depthWrite: !F });
const chainUnits = balls(N, D.unit_radius, unitMat);
const chainLinks = sticks(N - 1, D.link_radius, new THREE.MeshStandardMaterial({ color: 0x37474f, roughness: 0.6 }));
// An exploration's plan is its pieces joined, whose waypoints have no clock of their
// own (each piece was timed when it was committed): its flight alone shows the chain.
if (!S) scene.add(chainUnits, chainLinks);
const unitsAt = (arr, i) => [...Array(N).keys()].map((u) => v3(arr, i * N + u));
const linksOf = (ps) => ps.slice(1).map((p, k) => [ps[k], p]);

// The flown chain: smaller orange units, and the head's flown trail.
let flownUnits = null, flownLinks = null;
if (F) {
  const fn = F.t.length;
  const trail = sticks(Math.max(fn - 1, 1), trailRadius * 0.8, new THREE.MeshLambertMaterial({ color: FLOWN }));
  const fh = [...Array(fn).keys()].map((i) => v3(F.units, i * N));
  trail.setPoints(fh.slice(1).map((h, i) => [fh[i], h]));
  scene.add(trail);
  flownUnits = balls(N, D.unit_radius * 0.55, new THREE.MeshLambertMaterial({ color: FLOWN }));
  flownLinks = sticks(N - 1, D.link_radius * 1.2, new THREE.MeshLambertMaterial({ color: FLOWN }));
  scene.add(flownUnits, flownLinks);
}

// Time: waypoint times are those of `arc sim` with its default limits (a smoothstep
// ramp stands in for its speed profile on translations); the flight's are its own
// recorded times. Both start at 0 with the start hold.
const tEnd = S ? F.t[F.t.length - 1] : Math.max(W.t[wn - 1], F ? F.t[F.t.length - 1] : 0);
const slider = document.getElementById('time');
slider.max = String(tEnd);
const lastAtOrBefore = (ts, t) => { let lo = 0, hi = ts.length - 1; while (lo < hi) { const m = (lo + hi + 1) >> 1; if (ts[m] <= t) lo = m; else hi = m - 1; } return lo; };
const info = document.getElementById('info');
let now = 0;
function setTime(t) {
  now = Math.min(Math.max(Number.isFinite(t) ? t : 0, 0), tEnd);
  slider.value = String(now);
  const i = lastAtOrBefore(W.t, now);
  let ps = unitsAt(W.units, i);
  // On a translation every unit moves by the same vector, so the chain between the
  // two waypoints is exact; a shape change shows the waypoint left until the next.
  let moving = '';
  if (i + 1 < wn && now > W.leave[i]) {
    const qs = unitsAt(W.units, i + 1);
    const shift = new THREE.Vector3().subVectors(qs[0], ps[0]);
    if (qs.every((q, u) => new THREE.Vector3().subVectors(q, ps[u]).distanceTo(shift) < 1e-3)) {
      const f = Math.min((now - W.leave[i]) / Math.max(W.t[i + 1] - W.leave[i], 1e-9), 1);
      const s = f * f * (3 - 2 * f);
      ps = ps.map((p) => p.clone().addScaledVector(shift, s));
      moving = `, translating to waypoint ${i + 1}`;
    } else moving = `, changing shape to waypoint ${i + 1}`;
  }
  chainUnits.setPoints(ps);
  chainLinks.setPoints(linksOf(ps));
  const col = new THREE.Color(KINDS[W.kind[i]][0]);
  ps.forEach((_, u) => chainUnits.setColorAt(u, u === 0 ? col.clone().offsetHSL(0, 0, -0.15) : col));
  chainUnits.instanceColor.needsUpdate = true;
  let text = `t = ${now.toFixed(2)} s of ${tEnd.toFixed(2)} s`;
  if (!S) text += `; waypoint ${i} of ${wn - 1}: ${W.source[i] || W.kind[i]} (reached at ${W.t[i].toFixed(2)} s)${moving}`;
  let head = ps[0];
  if (F) {
    const j = lastAtOrBefore(F.t, now);
    const fp = unitsAt(F.units, j);
    if (S) head = fp[0];
    flownUnits.setPoints(fp);
    flownLinks.setPoints(linksOf(fp));
    text += `; flown chain at ${F.t[j].toFixed(2)} s`;
  }
  if (seenMesh) {
    const k = S.t.length ? lastAtOrBefore(S.t, now) + (S.t[0] <= now ? 1 : 0) : 0;
    seenMesh.count = k;
    text += `; ${k} of ${S.t.length} boxes seen occupied`;
  }
  info.textContent = text;
  if (follow.checked) { target.copy(head); place(); }
  render();
}
// Follow: the camera keeps its direction and distance from the head (long routes).
const follow = document.getElementById('follow');

// Framing: the box around the chain's path, the flight and the goal.
const box = new THREE.Box3();
for (let k = 0; k < W.units.length / 3; k++) box.expandByPoint(v3(W.units, k));
if (F) for (let k = 0; k < F.units.length / 3; k++) box.expandByPoint(v3(F.units, k));
if (D.goal) box.expandByPoint(new THREE.Vector3().fromArray(D.goal.center));
box.expandByScalar(D.unit_radius * 2);
const target = box.getCenter(new THREE.Vector3());
const size = box.getSize(new THREE.Vector3());
const orbit = { az: -Math.PI / 2 - 0.5, el: 0.9, r: 1 };
const frameR = (0.5 * size.length()) / Math.sin(THREE.MathUtils.degToRad(camera.fov) / 2) * 0.75 + 1;
orbit.r = frameR;
function place() {
  camera.position.set(
    target.x + orbit.r * Math.cos(orbit.el) * Math.cos(orbit.az),
    target.y + orbit.r * Math.cos(orbit.el) * Math.sin(orbit.az),
    target.z + orbit.r * Math.sin(orbit.el));
  camera.lookAt(target);
  render();
}

// The cut height: by default just above the highest unit (the framing box adds 2 r_u),
// so that ceilings and high walls do not hide the chain.
const cutIn = document.getElementById('cut'), cutV = document.getElementById('cutv');
let zTop = box.max.z;
for (const idx of [D.boxes.occupied, D.boxes.unknown]) for (let k = 2; k < idx.length; k += 3) zTop = Math.max(zTop, D.boxes.origin[2] + D.boxes.size * (idx[k] + 0.5));
cutIn.min = String(Math.floor(box.min.z)); cutIn.max = String(Math.ceil(Math.max(zTop, box.max.z)) + 1);
function setCut(z) { cut.constant = z; cutIn.value = String(z); cutV.textContent = `${z.toFixed(1)} m`; render(); }
cutIn.addEventListener('input', () => setCut(Number(cutIn.value)));
follow.addEventListener('change', () => {
  if (follow.checked) orbit.r = Math.min(orbit.r, 12 * D.unit_radius * N + 2);
  else { target.copy(box.getCenter(new THREE.Vector3())); orbit.r = frameR; }
  setTime(now); place();
});

let frame = 0;
function render() { if (!frame) frame = requestAnimationFrame(() => { frame = 0; renderer.render(scene, camera); }); }

// Orbit: drag turns around the target, right- or shift-drag pans, the wheel zooms.
let drag = null;
const el = renderer.domElement;
el.addEventListener('contextmenu', (e) => e.preventDefault());
el.addEventListener('pointerdown', (e) => { drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey }; el.setPointerCapture(e.pointerId); });
el.addEventListener('pointerup', () => { drag = null; });
el.addEventListener('pointermove', (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX; drag.y = e.clientY;
  if (drag.pan) {
    const k = orbit.r * 0.0015;
    const right = new THREE.Vector3().setFromMatrixColumn(camera.matrix, 0);
    const up = new THREE.Vector3().setFromMatrixColumn(camera.matrix, 1);
    target.addScaledVector(right, -dx * k).addScaledVector(up, dy * k);
  } else {
    orbit.az -= dx * 0.008;
    orbit.el = Math.min(Math.max(orbit.el + dy * 0.008, -1.5), 1.5);
  }
  place();
});
el.addEventListener('wheel', (e) => { e.preventDefault(); orbit.r *= Math.exp(e.deltaY * 0.001); place(); }, { passive: false });
window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight; camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight); render();
});

// Play / pause, and the time in the address (#t=SECONDS).
const play = document.getElementById('play'), speed = document.getElementById('speed');
let playing = false, last = 0;
function tick(ms) {
  if (!playing) return;
  if (last) setTime(now + ((ms - last) / 1000) * Number(speed.value));
  last = ms;
  if (now >= tEnd) { toggle(); return; }
  requestAnimationFrame(tick);
}
function toggle() {
  playing = !playing; play.textContent = playing ? 'pause' : 'play'; last = 0;
  if (playing) { if (now >= tEnd) setTime(0); requestAnimationFrame(tick); } else history.replaceState(null, '', `#t=${now.toFixed(2)}`);
}
play.addEventListener('click', toggle);
window.addEventListener('keydown', (e) => { if (e.code === 'Space' && e.target.tagName !== 'INPUT') { e.preventDefault(); toggle(); } });
slider.addEventListener('input', () => setTime(Number(slider.value)));
slider.addEventListener('change', () => history.replaceState(null, '', `#t=${now.toFixed(2)}`));
// `#ui=0` hides the panels (for pictures and checks of the drawing alone);
// `#follow=1` starts with the camera on the chain.
const hashUi = () => !/(^#|&)ui=0/.test(location.hash);
const hashTime = () => { const m = /(^#|&)t=([-+0-9.eE]+)/.exec(location.hash); return m ? Number(m[2]) : 0; };
function showUi() { for (const id of ['panel', 'legend']) document.getElementById(id).hidden = !hashUi(); }
window.addEventListener('hashchange', () => { showUi(); setTime(hashTime()); });

// The legend: only what this scene holds.
const legend = document.getElementById('legend');
const entry = (color, text) => { const d = document.createElement('div'); const i = document.createElement('i'); i.style.background = '#' + new THREE.Color(color).getHexString(); d.append(i, text); legend.append(d); };
entry(ROUTE, 'head route (plan)');
for (const k of Object.keys(KINDS)) if (W.kind.includes(k) && k !== 'start') entry(KINDS[k][0], KINDS[k][1]);
if (F) entry(FLOWN, 'flown chain and head trail');
if (D.goal) entry(GOAL, `goal region (${D.goal.radius} m)`);
if (S) entry(SEEN, `seen occupied by then${S.scale > 1 ? ` (merged ${S.scale}x${S.scale}x${S.scale} voxels)` : ''}`);
if (D.boxes.occupied.length) entry(OCC, `occupied${S ? ' (the world, faint)' : ''}${D.boxes.scale > 1 ? ` (merged ${D.boxes.scale}x${D.boxes.scale}x${D.boxes.scale} voxels)` : ''}`);
if (D.boxes.unknown.length) entry(UNK, 'unknown, counted as occupied');

setCut(Math.min(box.max.z, Number(cutIn.max)));
showUi();
if (/(^#|&)follow=1/.test(location.hash)) { follow.checked = true; orbit.r = Math.min(orbit.r, 12 * D.unit_radius * N + 2); }
place();
setTime(hashTime());
renderer.render(scene, camera);
const ready = document.createElement('div');
ready.id = 'arc-view-ready'; ready.hidden = true;
document.body.append(ready);
