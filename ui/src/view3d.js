// view3d.js: the machine in 3-D (three.js): base, six legs coloured by how much of their
// range they use, the platform with what it carries, the tool, and the open program's path
// (rapids dashed, feeds solid, G141/G142 moves in their own colour, the part already run
// dimmed, the current line bright). Z is up, millimetres throughout.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const DEG = Math.PI / 180;
const COLORS = { feed: 0x4fb3ff, comp: 0xffa040, contour: 0xff60ff, rapid: 0xd0d0d0, done: 0x4a5560,
  current: 0xffff40, problem: 0xff3030 };

// Platform orientation as the kinematics has it: R = Rz(C)·Ry(B)·Rx(A).
function rotation(a, b, c) {
  return new THREE.Matrix4().makeRotationFromEuler(new THREE.Euler(a * DEG, b * DEG, c * DEG, 'ZYX'));
}

function legColor(u) {   // 0..1 of the leg's range used; red near either end
  const edge = Math.min(u, 1 - u);
  if (edge < 0) return new THREE.Color(0xff0000);
  if (edge < 0.05) return new THREE.Color(0xff3030);
  if (edge < 0.15) return new THREE.Color(0xffc040);
  return new THREE.Color(0x40c060);
}

export class MachineView {
  constructor(canvas) {
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setClearColor(0x0f1215);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 1, 20000);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.addEventListener('change', () => this.draw());
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.55));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(800, -600, 1500);
    this.scene.add(sun);
    this.machine = new THREE.Group();
    this.scene.add(this.machine);
    this.platform = new THREE.Group();
    this.scene.add(this.platform);
    this.pathWorld = new THREE.Group();      // path drawn in the machine frame
    this.scene.add(this.pathWorld);
    this.pathPlatform = new THREE.Group();   // path drawn on the workpiece the platform carries
    this.platform.add(this.pathPlatform);
    this.legs = [];
    this.geo = null;
    this.path = null;
    this.radius = 600;
    this.pending = false;
    new ResizeObserver(() => this.resize()).observe(canvas.parentElement);
    this.resize();
    this.setView('iso');
  }

  resize() {
    const el = this.canvas.parentElement;
    const w = Math.max(el.clientWidth, 50), h = Math.max(el.clientHeight, 50);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.draw();
  }

  draw() {   // at most once per frame, only when something changed
    if (this.pending) return;
    this.pending = true;
    requestAnimationFrame(() => { this.pending = false; this.renderer.render(this.scene, this.camera); });
  }

  setGeometry(info) {
    this.machine.clear();
    for (const c of [...this.platform.children]) if (c !== this.pathPlatform) this.platform.remove(c);
    this.legs = [];
    const g = info.geometry;
    this.geo = g || null;
    const grid = new THREE.GridHelper(1600, 16, 0x334049, 0x232a31);
    grid.rotation.x = Math.PI / 2;
    this.machine.add(grid);
    this.machine.add(new THREE.AxesHelper(150));
    if (!g) { this.draw(); return; }
    const rb = Math.max(...g.base.map((b) => Math.hypot(b[0], b[1])));
    this.radius = rb;
    const base = new THREE.Mesh(new THREE.CylinderGeometry(rb * 1.12, rb * 1.12, 20, 48),
      new THREE.MeshStandardMaterial({ color: 0x59636e, metalness: 0.3, roughness: 0.7 }));
    base.rotation.x = Math.PI / 2;
    base.position.z = Math.min(...g.base.map((b) => b[2])) - 10;
    this.machine.add(base);
    const jointMat = new THREE.MeshStandardMaterial({ color: 0xb0b8c0 });
    for (const b of g.base) {
      const s = new THREE.Mesh(new THREE.SphereGeometry(14, 16, 12), jointMat);
      s.position.set(b[0], b[1], b[2]);
      this.machine.add(s);
    }
    for (let i = 0; i < g.base.length; i++) {
      const leg = new THREE.Mesh(new THREE.CylinderGeometry(9, 9, 1, 12),
        new THREE.MeshStandardMaterial({ color: 0x40c060 }));
      this.machine.add(leg);
      this.legs.push(leg);
    }
    // the platform: a plate through its joints, in the platform frame
    const shape = new THREE.Shape(g.platform.map((p) => new THREE.Vector2(p[0], p[1])));
    const plate = new THREE.Mesh(new THREE.ExtrudeGeometry(shape, { depth: 16, bevelEnabled: false }),
      new THREE.MeshStandardMaterial({ color: 0x8090a0, metalness: 0.2, roughness: 0.6 }));
    plate.position.z = -16;
    this.platform.add(plate);
    for (const p of g.platform) {
      const s = new THREE.Mesh(new THREE.SphereGeometry(11, 16, 12), jointMat);
      s.position.set(p[0], p[1], p[2]);
      this.platform.add(s);
    }
    const tip = new THREE.Vector3(...g.tool_tip);
    const axis = new THREE.Vector3(...g.tool_axis).normalize();
    const tool = new THREE.Group();
    const cutter = new THREE.Mesh(new THREE.CylinderGeometry(4, 4, 60, 16),
      new THREE.MeshStandardMaterial({ color: 0xe0e0e0, metalness: 0.8, roughness: 0.3 }));
    cutter.position.y = 30;
    const spindle = new THREE.Mesh(new THREE.CylinderGeometry(40, 40, 160, 24),
      new THREE.MeshStandardMaterial({ color: 0x3c6e9e }));
    spindle.position.y = 140;
    tool.add(cutter, spindle);
    // the group's +Y runs from the tip back up the tool (against TOOL_AXIS)
    tool.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), axis.clone().negate());
    tool.position.copy(tip);
    if (g.carries === 'spindle') {
      this.platform.add(tool);
    } else {
      this.machine.add(tool);
      const stock = new THREE.Mesh(new THREE.BoxGeometry(220, 220, 40),
        new THREE.MeshStandardMaterial({ color: 0xc9a86a, transparent: true, opacity: 0.35 }));
      stock.position.z = 20;
      this.platform.add(stock);
    }
    this.draw();
  }

  setPose(pose, legs) {   // pose: machine X Y Z A B C; legs: the status's per-leg objects
    if (!pose) return;
    const R = rotation(pose[3], pose[4], pose[5]);
    this.platform.position.set(pose[0], pose[1], pose[2]);
    this.platform.quaternion.setFromRotationMatrix(R);
    if (this.geo) {
      const t = new THREE.Vector3(pose[0], pose[1], pose[2]);
      this.geo.platform.forEach((p, i) => {
        const top = new THREE.Vector3(...p).applyMatrix4(R).add(t);
        const bot = new THREE.Vector3(...this.geo.base[i]);
        const leg = this.legs[i];
        const d = top.clone().sub(bot);
        leg.position.copy(bot).addScaledVector(d, 0.5);
        leg.scale.set(1, d.length(), 1);
        leg.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), d.normalize());
        const l = legs && legs[i];
        if (l) leg.material.color.copy(legColor((l.length - l.min) / (l.max - l.min)));
      });
    }
    this.draw();
  }

  // The path: preview from program.preview (points of the pose in machine coordinates).
  setPath(pv) {
    for (const g of [this.pathWorld, this.pathPlatform]) {
      for (const c of g.children) { c.geometry.dispose(); c.material.dispose(); }
      g.clear();
    }
    this.path = null;
    if (!pv || pv.points < 2) { this.draw(); return; }
    const g = this.geo, onPlatform = !g || g.carries !== 'spindle';
    const tip = g ? new THREE.Vector3(...g.tool_tip) : new THREE.Vector3();
    // a pose (X Y Z A B C in thousandths) to where the tool tip draws it
    const place = (um, n) => {
      const out = new Float32Array(n * 3), v = new THREE.Vector3();
      for (let i = 0; i < n; i++) {
        const q = um.slice(i * 6, i * 6 + 6).map((x) => x / 1000);
        const R = rotation(q[3], q[4], q[5]);
        const t = new THREE.Vector3(q[0], q[1], q[2]);
        if (!g) v.copy(t);
        else if (onPlatform) v.copy(tip).sub(t).applyMatrix4(R.clone().transpose());  // tip on the work
        else v.copy(tip).applyMatrix4(R).add(t);                                      // tip in the frame
        out[i * 3] = v.x; out[i * 3 + 1] = v.y; out[i * 3 + 2] = v.z;
      }
      return out;
    };
    const n = pv.points, P = place(pv.pts_um, n);
    const seg = (kindWanted) => {
      const idx = [];
      for (let i = 1; i < n; i++) if (kindWanted(pv.kind[i])) idx.push(i);
      const pos = new Float32Array(idx.length * 6);
      idx.forEach((i, j) => { pos.set(P.subarray((i - 1) * 3, i * 3), j * 6); pos.set(P.subarray(i * 3, i * 3 + 3), j * 6 + 3); });
      const geom = new THREE.BufferGeometry();
      geom.setAttribute('position', new THREE.BufferAttribute(pos, 3));
      return { geom, idx };
    };
    const rapid = seg((k) => k === 0), cut = seg((k) => k !== 0);
    const rl = new THREE.LineSegments(rapid.geom, new THREE.LineDashedMaterial({ color: COLORS.rapid, dashSize: 3, gapSize: 3 }));
    rl.computeLineDistances();
    const colors = new Float32Array(cut.idx.length * 6);
    cut.idx.forEach((i, j) => {
      const c = new THREE.Color(pv.kind[i] === 2 ? COLORS.comp : COLORS.feed);
      for (let e = 0; e < 2; e++) colors.set([c.r, c.g, c.b], j * 6 + e * 3);
    });
    cut.geom.setAttribute('color', new THREE.BufferAttribute(colors, 3));
    const cl = new THREE.LineSegments(cut.geom, new THREE.LineBasicMaterial({ vertexColors: true }));
    const hl = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: COLORS.current }));
    const parent = onPlatform ? this.pathPlatform : this.pathWorld;
    parent.add(rl, cl, hl);
    // G141/G142: the programmed contour beside the tool path the compensation made
    const nc = (pv.contour_line || []).length;
    if (nc > 1) {
      const C = place(pv.contour_um, nc), pos = [];
      for (let i = 1; i < nc; i++) {
        if (pv.contour_first[i]) continue;   // a new run starts here
        pos.push(...C.subarray((i - 1) * 3, i * 3), ...C.subarray(i * 3, i * 3 + 3));
      }
      const geom = new THREE.BufferGeometry();
      geom.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pos), 3));
      parent.add(new THREE.LineSegments(geom, new THREE.LineBasicMaterial({ color: COLORS.contour })));
    }
    // which segments belong to each line, for highlighting
    const byLine = new Map();
    for (let i = 1; i < n; i++) {
      const l = pv.line[i];
      if (!byLine.has(l)) byLine.set(l, []);
      byLine.get(l).push(i);
    }
    this.path = { pv, P, cut, cl, hl, byLine, doneUpTo: 0, parent };
    this.draw();
  }

  // The program is at `line`: segments before the first one of that line are done.
  setLine(line, color = COLORS.current) {
    const p = this.path;
    if (!p) return;
    const segs = p.byLine.get(line) || [];
    const pos = new Float32Array(segs.length * 6);
    segs.forEach((i, j) => { pos.set(p.P.subarray((i - 1) * 3, i * 3), j * 6); pos.set(p.P.subarray(i * 3, i * 3 + 3), j * 6 + 3); });
    p.hl.geometry.dispose();
    p.hl.geometry = new THREE.BufferGeometry();
    p.hl.geometry.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    p.hl.material.color.set(color);
    this.draw();
  }

  setProgress(line, running) {
    const p = this.path;
    if (!p) return;
    const first = line > 0 && p.byLine.get(line) ? p.byLine.get(line)[0] : (running ? 0 : -1);
    const upTo = first < 0 ? 0 : first;
    if (upTo === p.doneUpTo) return;
    const col = p.cut.geom.getAttribute('color');
    const done = new THREE.Color(COLORS.done);
    p.cut.idx.forEach((i, j) => {
      const was = i < p.doneUpTo, now = i < upTo;
      if (was === now) return;
      const c = now ? done : new THREE.Color(p.pv.kind[i] === 2 ? COLORS.comp : COLORS.feed);
      for (let e = 0; e < 2; e++) col.array.set([c.r, c.g, c.b], j * 6 + e * 3);
    });
    col.needsUpdate = true;
    p.doneUpTo = upTo;
    this.draw();
  }

  setView(name) {
    let target = new THREE.Vector3(0, 0, 400), dist = this.radius * 4.2;
    if (name === 'fit' && this.path) {
      const box = new THREE.Box3().setFromBufferAttribute(new THREE.BufferAttribute(this.path.P, 3));
      box.applyMatrix4(this.path.parent.matrixWorld);
      target = box.getCenter(new THREE.Vector3());
      dist = Math.max(box.getSize(new THREE.Vector3()).length() * 1.6, 450);
      name = 'iso';
    }
    const dir = { iso: [1, -1.3, 0.9], top: [0, -0.001, 1], front: [0, -1, 0.001], side: [1, 0, 0.001] }[name] || [1, -1.3, 0.9];
    const d = new THREE.Vector3(...dir).normalize().multiplyScalar(dist);
    this.camera.position.copy(target).add(d);
    this.controls.target.copy(target);
    this.controls.update();
    this.draw();
  }
}
