// The 3D scene of a trace: floor, bodies with their shapes, fingers (HIP, god-object, force),
// contact points of the bodies (floor and body-body) with their forces.
// World frame as in graspsim: metres, z up. Poses are set from the trace's float64 values as they
// are (JavaScript numbers are float64), so a drawn pose is the recorded one to the bit.
import * as THREE from 'three';

export const STATE_COLOURS = ['#9e9e9e', '#2e9e44', '#e4572e'];   // 0 free, 1 stick, 2 slip
const FORCE_SCALE = 0.01;       // m of arrow per N
const POINT_PAD = 0.004;        // m: god-object radius drawn for a point pad (radius 0)
const HIP_RADIUS = 0.002;       // m
export const CONTACT_COLOURS = { floor: '#00897b', body: '#8d6e63' };   // floor points, body-body points
const CONTACT_RADIUS = 0.0015;  // m: a contact point's dot

// Sets an arrow from `origin` along `force` (N), FORCE_SCALE m per N (the fingers' scale); hidden
// for a force of (nearly) 0.
function setArrow(arrow, origin, force) {
  const n = Math.hypot(force[0], force[1], force[2]);
  arrow.visible = n > 1e-9;
  if (!arrow.visible) return;
  arrow.position.copy(origin);
  arrow.setDirection(new THREE.Vector3(force[0] / n, force[1] / n, force[2] / n));
  const len = n * FORCE_SCALE;
  arrow.setLength(len, Math.min(0.3 * len, 0.01), Math.min(0.15 * len, 0.005));
}

// One contact point: a dot and its force's arrow, in the colour of its kind. Drawn over
// everything (no depth test): a floor point is under the floor by its penetration, and its
// arrow, about as long, would be hidden by the floor's plane.
function makeContact(kind) {
  const colour = CONTACT_COLOURS[kind];
  const dot = new THREE.Mesh(new THREE.SphereGeometry(CONTACT_RADIUS, 10, 6),
                             new THREE.MeshBasicMaterial({ color: colour, depthTest: false }));
  const arrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 0.01, colour);
  arrow.line.material.depthTest = arrow.cone.material.depthTest = false;
  dot.renderOrder = arrow.line.renderOrder = arrow.cone.renderOrder = 1;
  return { kind, dot, arrow, force: [0, 0, 0], a: -2, b: 0, row: -1 };
}

// A body's geometry in its body frame (origin at the centre of mass; cylinder and capsule
// along body z, three.js builds them along y).
function bodyGeometry(shape) {
  const r = shape.radius, hl = shape.half_length, h = shape.half_extents;
  switch (shape.kind) {
    case 'box': return new THREE.BoxGeometry(2 * h[0], 2 * h[1], 2 * h[2]);
    case 'sphere': return new THREE.SphereGeometry(r, 32, 16);
    case 'cylinder': return new THREE.CylinderGeometry(r, r, 2 * hl, 32).rotateX(Math.PI / 2);
    case 'capsule': return new THREE.CapsuleGeometry(r, 2 * hl, 8, 24).rotateX(Math.PI / 2);
    case 'convex': case 'mesh': {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(shape.vertices, 3));
      g.setIndex(shape.triangles);
      const flat = g.toNonIndexed();   // one normal per face: facets read as facets
      flat.computeVertexNormals();
      return flat;
    }
    default: return null;
  }
}

// A body; `ghost`: the second run of an overlay, orange and mostly transparent.
function makeBody(body, ghost = false) {
  const group = new THREE.Group();
  group.name = body.name;
  let geometry = bodyGeometry(body.shape);
  const known = geometry !== null;
  if (!known) geometry = new THREE.BoxGeometry(0.02, 0.02, 0.02);   // placeholder: shape unknown
  const material = new THREE.MeshStandardMaterial({
    color: ghost ? 0xe67e22 : known ? 0x6b8cc7 : 0xbbbbbb, roughness: 0.6, metalness: 0.0,
    transparent: true, opacity: ghost ? 0.22 : known ? 0.6 : 0.5, wireframe: !known, depthWrite: !ghost });
  group.add(new THREE.Mesh(geometry, material));
  if (known) group.add(new THREE.LineSegments(new THREE.EdgesGeometry(geometry, 20),
                                              new THREE.LineBasicMaterial({ color: ghost ? 0xb35400 : 0x26324a,
                                                                            transparent: ghost, opacity: ghost ? 0.5 : 1 })));
  return group;
}

// The grasp axis of a body held by two fingers (a line between their god-objects, as the grasp
// rule takes it) and its torsion: an arc about the axis at its middle, turning the way the
// torque does (right-hand rule about first -> second finger), drawn while the torsion is not 0.
const TORSION_ARC = 0.012;   // m: the arc's radius
function makeGrasp() {
  const colour = 0x8e44ad;
  const axis = new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3()]),
                              new THREE.LineBasicMaterial({ color: colour }));
  const points = [];
  for (let k = 0; k <= 48; k++) points.push(new THREE.Vector3(Math.cos(k * Math.PI / 32), Math.sin(k * Math.PI / 32), 0));
  const arc = new THREE.Group();
  arc.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(points), new THREE.LineBasicMaterial({ color: colour })));
  // Arrowhead at the arc's end (angle 3 pi / 2, point (0, -1, 0), heading +x).
  const head = new THREE.Mesh(new THREE.ConeGeometry(0.12, 0.3, 12).rotateZ(-Math.PI / 2),
                              new THREE.MeshBasicMaterial({ color: colour }));
  head.position.set(0, -1, 0);
  arc.add(head);
  arc.scale.setScalar(TORSION_ARC);
  axis.visible = arc.visible = false;
  return { axis, arc, held: false, torsion: 0, ends: null };
}

function makeFinger(finger) {
  const padRadius = finger.radius > 0 ? finger.radius : POINT_PAD;
  const go = new THREE.Mesh(new THREE.SphereGeometry(padRadius, 24, 12),
                            new THREE.MeshStandardMaterial({ color: STATE_COLOURS[0], roughness: 0.4 }));
  const hip = new THREE.Mesh(new THREE.SphereGeometry(HIP_RADIUS, 12, 8),
                             new THREE.MeshBasicMaterial({ color: 0x222222 }));
  const spring = new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), new THREE.Vector3()]),
                                new THREE.LineBasicMaterial({ color: 0x444444 }));
  const arrow = new THREE.ArrowHelper(new THREE.Vector3(1, 0, 0), new THREE.Vector3(), 0.01, 0xd81b60);
  // The friction circle: unit circle in its xy plane, scaled to mu depth, laid on the face.
  const points = [];
  for (let k = 0; k < 64; k++) points.push(new THREE.Vector3(Math.cos(k * Math.PI / 32), Math.sin(k * Math.PI / 32), 0));
  const circle = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(points),
                                    new THREE.LineBasicMaterial({ color: 0xf39c12 }));
  return { name: finger.name, go, hip, spring, arrow, circle, colour: STATE_COLOURS[0], state: 0 };
}

export class SceneView {
  constructor(container, scene) {
    this.container = container;
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xf4f4f2);
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    container.appendChild(this.renderer.domElement);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.001, 100);
    this.camera.up.set(0, 0, 1);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8a80, 2.0));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(0.5, -1, 2);
    this.scene.add(sun);
    if (scene.floor.enabled) this.addFloor(scene.floor.height);
    this.scene.add(new THREE.AxesHelper(0.05));
    this.bodies = scene.bodies.map((b) => { const g = makeBody(b); this.scene.add(g); return g; });
    this.fingers = scene.fingers.map((f) => {
      const v = makeFinger(f);
      this.scene.add(v.go, v.hip, v.spring, v.arrow, v.circle);
      return v;
    });
    this.grasps = scene.bodies.map(() => { const g = makeGrasp(); this.scene.add(g.axis, g.arc); return g; });
    this.contactPool = { floor: [], body: [] };   // drawn objects, reused from tick to tick
    this.contacts = [];                            // the ones shown now, in the trace's row order
    this.ghosts = [];
    this.ghostFingers = [];
    this.resize();
    // The stage's size follows the window and the timeline's wrapping.
    new ResizeObserver(() => this.resize()).observe(container);
  }

  // The second run of an overlay: its bodies ghosted, its god-objects as faint spheres.
  addGhost(scene) {
    this.ghosts = scene.bodies.map((b) => { const g = makeBody(b, true); this.scene.add(g); return g; });
    this.ghostFingers = scene.fingers.map((f) => {
      const m = new THREE.Mesh(new THREE.SphereGeometry(f.radius > 0 ? f.radius : POINT_PAD, 16, 8),
                               new THREE.MeshBasicMaterial({ color: 0xe67e22, transparent: true, opacity: 0.35, depthWrite: false }));
      m.name = f.name;
      this.scene.add(m);
      return m;
    });
  }
  setGhostBody(i, p, q) {
    this.ghosts[i].position.set(p[0], p[1], p[2]);
    this.ghosts[i].quaternion.set(q[1], q[2], q[3], q[0]);
  }
  setGhostFinger(j, go) { this.ghostFingers[j].position.set(go[0], go[1], go[2]); }

  // Body i's grasp: held between god-objects a and b (world, m) with `torsion` (N m), or not
  // held (a null).
  setGrasp(i, a, b, torsion) {
    const g = this.grasps[i];
    g.held = a !== null;
    g.axis.visible = g.held;
    g.arc.visible = g.held && torsion !== 0;
    g.torsion = g.held ? torsion : 0;
    g.ends = g.held ? [a, b] : null;
    if (!g.held) return;
    const A = new THREE.Vector3(...a), B = new THREE.Vector3(...b);
    g.axis.geometry.setFromPoints([A, B]);
    const u = B.clone().sub(A).normalize();
    g.arc.position.copy(A).add(B).multiplyScalar(0.5);
    g.arc.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), torsion >= 0 ? u : u.negate());
  }

  // The camera along an axis through `target`, as far from it as it is now: 'y' from the front
  // (-y, looking along +y), 'x' from the side (+x, looking along -x), 'z' from above (looking
  // down; a hair off the vertical, which the orbit controls keep z up with).
  lookAlong(axis, target) {
    const d = this.camera.position.distanceTo(target);
    const from = { x: [1, 0, 0], y: [0, -1, 0], z: [0, -1e-4, 1] }[axis];
    const v = new THREE.Vector3(...from).normalize().multiplyScalar(d);
    this.camera.position.copy(target).add(v);
    this.camera.lookAt(target);
  }

  addFloor(height) {
    const grid = new THREE.GridHelper(1.0, 50, 0x777777, 0xb5b1a6);   // 2 cm squares over 1 m
    grid.rotateX(Math.PI / 2);
    grid.position.z = height;
    this.scene.add(grid);
    const plane = new THREE.Mesh(new THREE.PlaneGeometry(1.0, 1.0),
                                 new THREE.MeshStandardMaterial({ color: 0xe6e2d8, roughness: 1 }));
    plane.position.z = height - 1e-4;   // under the grid lines, so they are not hidden
    this.scene.add(plane);
  }

  resize() {
    const w = this.container.clientWidth, h = this.container.clientHeight;
    this.renderer.setSize(w, h);
    this.camera.aspect = w / Math.max(h, 1);
    this.camera.updateProjectionMatrix();
  }

  // Body i at position p (3) and quaternion q (w, x, y, z).
  setBody(i, p, q) {
    this.bodies[i].position.set(p[0], p[1], p[2]);
    this.bodies[i].quaternion.set(q[1], q[2], q[3], q[0]);
  }

  // Finger j: HIP, god-object, force, surface point (3 each, world), friction radius (m) and
  // contact state (0, 1, 2).
  setFinger(j, hip, go, force, surface, frictionRadius, state) {
    const f = this.fingers[j];
    f.hip.position.set(hip[0], hip[1], hip[2]);
    f.go.position.set(go[0], go[1], go[2]);
    f.spring.geometry.setFromPoints([f.go.position, f.hip.position]);
    f.state = state;
    f.colour = STATE_COLOURS[state] ?? '#000000';
    f.go.material.color.set(f.colour);
    setArrow(f.arrow, f.go.position, force);
    // The circle of radius mu depth about the surface point, in the face's plane: its normal is
    // (surface point - HIP) / depth. Hidden while free.
    const nx = surface[0] - hip[0], ny = surface[1] - hip[1], nz = surface[2] - hip[2];
    const depth = Math.hypot(nx, ny, nz);
    f.circle.visible = state !== 0 && depth > 0 && frictionRadius > 0;
    if (f.circle.visible) {
      f.circle.position.set(surface[0], surface[1], surface[2]);
      f.circle.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), new THREE.Vector3(nx / depth, ny / depth, nz / depth));
      f.circle.scale.setScalar(frictionRadius);
    }
  }

  // The contact points of one physics tick: each {row (of /contacts), a, b, point (m), force (N,
  // on b)}; a = -2 is the floor. Dots and arrows come from a pool per kind, the rest hidden.
  setContacts(rows) {
    const used = { floor: 0, body: 0 };
    this.contacts = rows.map((r) => {
      const kind = r.a === -2 ? 'floor' : 'body';
      const pool = this.contactPool[kind];
      if (used[kind] === pool.length) {
        const c = makeContact(kind);
        this.scene.add(c.dot, c.arrow);
        pool.push(c);
      }
      const c = pool[used[kind]++];
      c.row = r.row;
      c.a = r.a;
      c.b = r.b;
      c.force = r.force;
      c.dot.visible = true;
      c.dot.position.set(r.point[0], r.point[1], r.point[2]);
      setArrow(c.arrow, c.dot.position, r.force);
      return c;
    });
    for (const kind of ['floor', 'body']) {
      for (const c of this.contactPool[kind].slice(used[kind])) c.dot.visible = c.arrow.visible = false;
    }
  }

  // What setContacts drew, read back from the objects: per point its /contacts row, a, b, kind and colour, the
  // dot's position (m) and the force the arrow shows (N: its direction times its length / scale,
  // 0 when hidden) from the arrow's origin.
  drawnContacts() {
    return this.contacts.map((c) => {
      const dir = new THREE.Vector3(0, 1, 0).applyQuaternion(c.arrow.quaternion);   // ArrowHelper points along +y
      const n = c.arrow.visible ? c.arrow.cone.position.y / FORCE_SCALE : 0;        // the cone sits at the arrow's length
      return { row: c.row, a: c.a, b: c.b, kind: c.kind, colour: `#${c.dot.material.color.getHexString()}`,
               point: [c.dot.position.x, c.dot.position.y, c.dot.position.z],
               origin: [c.arrow.position.x, c.arrow.position.y, c.arrow.position.z],
               force: [dir.x * n, dir.y * n, dir.z * n] };
    });
  }

  // The camera looks at what is drawn now (bodies and fingers) from the front (-y), a little
  // above, far enough to see all of it; returns the point it looks at.
  frame() {
    const box = new THREE.Box3();
    for (const g of this.bodies) box.expandByObject(g);
    for (const f of this.fingers) box.expandByObject(f.go).expandByObject(f.hip);
    const centre = box.isEmpty() ? new THREE.Vector3() : box.getCenter(new THREE.Vector3());
    const size = Math.max(box.isEmpty() ? 0 : box.getSize(new THREE.Vector3()).length(), 0.05);
    this.camera.position.set(centre.x + 0.5 * size, centre.y - 1.4 * size, centre.z + 0.6 * size);
    return centre;
  }

  render() { this.renderer.render(this.scene, this.camera); }
}
