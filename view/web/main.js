// The page of `graspsim view`: loads /scene.json and /trace.bin (view/README.md, "Data path"),
// and with a second run /b/scene.json, /b/trace.bin and /compare.json; draws the trace at a
// cursor (a servo tick), runs the timeline and the time series. window.graspsimView is the hook
// the browser test reads (view/test).
import { OrbitControls } from 'three/addons/OrbitControls.js';
import { SceneView } from './draw.js';
import { Plots } from './plots.js';
import { allSeries, fingerForces, rowAt, valueAt } from './series.js';

const $ = (id) => document.getElementById(id);
const FINGER_COLOURS = ['#1f77b4', '#d62728', '#2ca02c', '#9467bd', '#8c564b'];
const BODY_COLOURS = ['#26324a', '#17becf', '#bcbd22', '#7f7f7f'];

// Typed-array views of the blob's columns, by name.
function columns(scene, buffer) {
  const out = {};
  for (const c of scene.blob) {
    out[c.name] = c.type === 'i8' ? new Int8Array(buffer, c.offset, c.length)
                                  : new Float64Array(buffer, c.offset, c.length);
  }
  return out;
}

const slice = (a, row, w) => Array.from(a.subarray(row * w, row * w + w));

// The JSON at `path`; with `optional`, null where the server has none (404).
async function getJson(path, optional = false) {
  const r = await fetch(path);
  if (optional && r.status === 404) return null;
  if (!r.ok) throw new Error(`${path}: HTTP ${r.status}`);
  return r.json();
}
async function getBlob(path) {
  const r = await fetch(path);
  if (!r.ok) throw new Error(`${path}: HTTP ${r.status}`);
  return r.arrayBuffer();
}
// A run: its scene and columns. The second run of an overlay is at b/; null when none is served.
async function loadRun(prefix, optional) {
  const scene = await getJson(`${prefix}scene.json`, optional);
  return scene && { scene, col: columns(scene, await getBlob(`${prefix}trace.bin`)) };
}

// The panels beside the scene: forces per finger (and B's, faint), heights, contact state.
function panels(a, sa, b, sb) {
  const forces = [], heights = [], states = [];
  a.scene.fingers.forEach((f, j) => {
    const colour = FINGER_COLOURS[j % FINGER_COLOURS.length];
    forces.push({ label: `${f.name} f_n`, colour, series: sa[`finger/${j}/fn`] },
                { label: 'f_t', colour, dash: [5, 3], series: sa[`finger/${j}/ft`] },
                { label: '\u03BC f_n', colour, dash: [1, 3], series: sa[`finger/${j}/limit`] });
    if (b && b.scene.fingers[j]) forces.push({ label: `B ${f.name} f_n`, colour, ghost: true, series: sb[`finger/${j}/fn`] });
    states.push({ label: f.name, colour: '#333', series: sa[`finger/${j}/state`] });
  });
  a.scene.bodies.forEach((o, i) => {
    const colour = BODY_COLOURS[i % BODY_COLOURS.length];
    heights.push({ label: o.name, colour, series: sa[`body/${i}/height`] });
    if (b && b.scene.bodies[i]) heights.push({ label: `B ${o.name}`, colour: '#e67e22', ghost: true, series: sb[`body/${i}/height`] });
  });
  const out = [];
  if (forces.length) out.push({ title: 'force, N', kind: 'lines', lines: forces });
  if (heights.length) out.push({ title: 'height, m', kind: 'lines', lines: heights });
  if (states.length) out.push({ title: 'contact', kind: 'bands', lines: states });
  return out;
}

async function start() {
  const t0 = performance.now();
  const first_scene = await getJson('scene.json', false);
  if (first_scene.live) { (await import('./live.js')).startLive(first_scene); return; }   // a running scenario (live.js)
  const [a, b] = await Promise.all([
    getBlob('trace.bin').then((buffer) => ({ scene: first_scene, col: columns(first_scene, buffer) })),
    loadRun('b/', true)]);
  const compare = b ? await getJson('compare.json') : null;
  const { scene, col } = a;
  const physicsTicks = col.physics_tick, hapticTicks = col.haptic_tick;
  const rate = scene.rates.servo;
  const first = Math.min(physicsTicks[0], hapticTicks.length ? hapticTicks[0] : Infinity);
  const last = physicsTicks[physicsTicks.length - 1];
  const divergent = compare ? compare.divergent_tick : null;

  $('title').textContent = `graspsim view: ${scene.scenario}`;
  $('trace').textContent = `${scene.trace} (${scene.rates.servo} / ${scene.rates.haptic} / ${scene.rates.physics} Hz, status ${scene.status})`;
  const notes = [scene.note];
  if (b) {
    notes.push(`B (orange, ghosted): ${b.scene.trace}` + (b.scene.note ? ` (${b.scene.note})` : '') + '. ' +
               (divergent === null ? 'The two runs do not differ.'
                                   : `First divergence at tick ${divergent} (t = ${(divergent / rate).toFixed(4)} s, ${compare.dataset}), marked red.`));
  }
  const note = notes.filter((n) => n).join(' ');
  if (note) { $('note').textContent = note; $('note').style.display = 'block'; }

  const view = new SceneView($('stage'), scene);
  if (b) view.addGhost(b.scene);
  const controls = new OrbitControls(view.camera, view.renderer.domElement);
  const series = allSeries(scene, col), seriesB = b ? allSeries(b.scene, b.col) : null;

  const scrub = $('scrub');
  scrub.min = first; scrub.max = last; scrub.value = first;
  let cursor = first, playing = false, speed = 1, lastFrame = null, frames = 0;
  let drawn = { tick: null, physicsRow: 0, hapticRow: 0 };
  const plots = new Plots($('plots'), panels(a, series, b, seriesB), [first, last], (t) => { setPlaying(false); seek(t); });
  if (divergent !== null) {
    plots.setMarker(divergent);
    const m = $('diverge');
    m.style.display = 'block';
    m.style.left = `${(100 * (divergent - first)) / Math.max(last - first, 1)}%`;
    m.title = `first divergence: tick ${divergent} (${compare.dataset})`;
    $('godiverge').style.display = 'inline-block';
    $('godiverge').onclick = () => { setPlaying(false); seek(divergent); };
  }

  // Body i's grasp at the cursor: held when its grasp area is not 0, between the two fingers
  // touching it at the /haptic row h (the grasp rule's pair).
  function grasp(i, p, h) {
    if (!(col[`body/${i}/grasp_area`][p] > 0)) return null;
    const on = scene.fingers.map((_, j) => j).filter((j) => col[`finger/${j}/state`][h] !== 0 && col[`finger/${j}/body`][h] === i);
    if (on.length !== 2) return null;
    return { fingers: on, a: slice(col[`finger/${on[0]}/god_object`], h, 3), b: slice(col[`finger/${on[1]}/god_object`], h, 3),
             torsion: col[`body/${i}/torsion`][p] };
  }

  // The /contacts rows of the physics step at row p (they are in tick order: a binary search).
  const contactTicks = col.contact_tick;
  function contactRows(p) {
    const t = physicsTicks[p], out = [];
    if (!scene.contacts || !contactTicks.length) return out;
    let lo = 0, hi = contactTicks.length;
    while (lo < hi) { const m = (lo + hi) >> 1; if (contactTicks[m] < t) lo = m + 1; else hi = m; }
    for (let r = lo; r < contactTicks.length && contactTicks[r] === t; r++) {
      out.push({ row: r, a: col['contact/a'][r], b: col['contact/b'][r], point: slice(col['contact/point'], r, 3),
                 force: slice(col['contact/force'], r, 3) });
    }
    return out;
  }

  function draw() {
    const tick = Math.floor(cursor);
    if (tick === drawn.tick) return;
    const p = rowAt(physicsTicks, tick), h = rowAt(hapticTicks, tick);
    view.setContacts(contactRows(p));
    const info = [];
    scene.bodies.forEach((o, i) => {
      view.setBody(i, slice(col[`body/${i}/position`], p, 3), slice(col[`body/${i}/quaternion`], p, 4));
      const g = grasp(i, p, h);
      view.setGrasp(i, g && g.a, g && g.b, g ? g.torsion : 0);
      info.push(`${o.name}: ${col[`body/${i}/floor_contacts`][p]} floor and ${col[`body/${i}/body_contacts`][p]} body contact points` +
                (g ? `; grasped by ${g.fingers.map((j) => scene.fingers[j].name).join(' and ')}, torsion ${g.torsion.toPrecision(3)} N m` : ''));
    });
    scene.fingers.forEach((f, j) => {
      const k = `finger/${j}/`;
      view.setFinger(j, slice(col[k + 'hip'], h, 3), slice(col[k + 'god_object'], h, 3), slice(col[k + 'force'], h, 3),
                     slice(col[k + 'surface_point'], h, 3), col[k + 'friction_radius'][h], col[k + 'state'][h]);
    });
    if (b) {
      const pb = rowAt(b.col.physics_tick, tick), hb = rowAt(b.col.haptic_tick, tick);
      b.scene.bodies.forEach((_, i) => view.setGhostBody(i, slice(b.col[`body/${i}/position`], pb, 3), slice(b.col[`body/${i}/quaternion`], pb, 4)));
      b.scene.fingers.forEach((_, j) => view.setGhostFinger(j, slice(b.col[`finger/${j}/god_object`], hb, 3)));
    }
    drawn = { tick, physicsRow: p, hapticRow: h };
    scrub.value = tick;
    plots.setCursor(tick);
    $('bodies').textContent = info.join('\n');
    $('clock').textContent = `tick ${tick}  t = ${(tick / rate).toFixed(4)} s of ${(last / rate).toFixed(3)} s  (physics row ${p})`;
  }
  function seek(tick) { cursor = Math.max(first, Math.min(last, tick)); draw(); }
  function setPlaying(on) {
    playing = on && cursor < last;
    if (on && cursor >= last) { cursor = first; playing = true; }
    lastFrame = null;
    $('play').textContent = playing ? '||' : '\u25B6';
  }
  // One tick of a loop back or forward: 'physics' and 'haptic' go to the next or previous row
  // of their table (one period from a tick of that loop), 'servo' one servo tick.
  function step(dir, loop = 'physics') {
    setPlaying(false);
    const t = Math.floor(cursor);
    if (loop === 'servo') return seek(t + Math.sign(dir));
    const ticks = loop === 'haptic' ? hapticTicks : physicsTicks;
    if (!ticks.length) return undefined;
    let r = rowAt(ticks, t);
    if (dir > 0 && ticks[r] <= t) r++;
    if (dir < 0 && ticks[r] >= t) r--;
    return seek(ticks[Math.max(0, Math.min(ticks.length - 1, r))]);
  }
  const lookAlong = (axis) => { view.lookAlong(axis, controls.target); controls.update(); };

  $('play').onclick = () => setPlaying(!playing);
  $('back').onclick = () => step(-1);
  $('fwd').onclick = () => step(+1);
  $('hback').onclick = () => step(-1, 'haptic');
  $('hfwd').onclick = () => step(+1, 'haptic');
  $('sback').onclick = () => step(-1, 'servo');
  $('sfwd').onclick = () => step(+1, 'servo');
  for (const axis of ['x', 'y', 'z']) $(`view${axis}`).onclick = () => lookAlong(axis);
  $('speed').onchange = (e) => { speed = Number(e.target.value); };
  scrub.oninput = () => { setPlaying(false); seek(Number(scrub.value)); };
  // Keys: space plays; arrows step one physics tick, with Shift one haptic tick, with Alt (or
  // , and .) one servo tick; x, y, z look along the axes.
  window.addEventListener('keydown', (e) => {
    const loop = e.shiftKey ? 'haptic' : e.altKey ? 'servo' : 'physics';
    if (e.key === ' ') { setPlaying(!playing); e.preventDefault(); }
    else if (e.key === 'ArrowRight') step(+1, loop);
    else if (e.key === 'ArrowLeft') step(-1, loop);
    else if (e.key === '.') step(+1, 'servo');
    else if (e.key === ',') step(-1, 'servo');
    else if (['x', 'y', 'z'].includes(e.key)) lookAlong(e.key);
  });

  function frame(now) {
    if (playing) {
      if (lastFrame !== null) cursor = Math.min(last, cursor + (now - lastFrame) / 1000 * speed * rate);
      lastFrame = now;
      if (cursor >= last) setPlaying(false);
    }
    draw();
    controls.update();
    view.render();
    frames++;
    requestAnimationFrame(frame);
  }
  draw();
  controls.target.copy(view.frame());   // framed on the first tick's bodies and fingers
  controls.update();
  requestAnimationFrame(frame);

  const v3 = (v) => [v.x, v.y, v.z];
  const poses = (groups) => groups.map((g) => ({ name: g.name, position: v3(g.position),
    quaternion: [g.quaternion.w, g.quaternion.x, g.quaternion.y, g.quaternion.z] }));
  window.graspsimView = {
    ready: true,
    loadMs: performance.now() - t0,                        // fetch and set-up of the scene
    scene,
    first, last,
    physicsTicks: Array.from(physicsTicks),
    hapticTicks: Array.from(hapticTicks),
    tick: () => drawn.tick,
    time: () => drawn.tick / rate,                          // s
    frames: () => frames,
    playing: () => playing,
    bodies: () => poses(view.bodies),
    fingers: () => view.fingers.map((f) => ({ name: f.name, state: f.state, colour: f.colour,
      circle: { visible: f.circle.visible, radius: f.circle.scale.x,
                centre: [f.circle.position.x, f.circle.position.y, f.circle.position.z] } })),
    // The time series at the cursor, as the plots show them: per finger f_n, f_t, mu f_n (N)
    // and state; per body height (m); and the forces recomputed from the cursor's /haptic row.
    series: () => ({
      fingers: scene.fingers.map((f, j) => ({ name: f.name, fn: valueAt(series[`finger/${j}/fn`], drawn.tick),
        ft: valueAt(series[`finger/${j}/ft`], drawn.tick), limit: valueAt(series[`finger/${j}/limit`], drawn.tick),
        state: valueAt(series[`finger/${j}/state`], drawn.tick), row: fingerForces(col, j, drawn.hapticRow) })),
      bodies: scene.bodies.map((o, i) => ({ name: o.name, height: valueAt(series[`body/${i}/height`], drawn.tick) })),
    }),
    // Each panel's cursor line in page coordinates, for a test's click.
    plotBox: (k) => { const r = plots.panels[k].cursor.getBoundingClientRect(); return { x: r.x, y: r.y, width: r.width, height: r.height }; },
    plotX: (k, tick) => plots.panels[k].xOf(tick),
    // The contact points drawn at the cursor's physics step, in the trace's row order: each
    // point and its force as drawn (dot position; arrow origin, direction times length / scale).
    contactsRecorded: scene.contacts,
    contacts: () => view.drawnContacts(),
    grasps: () => view.grasps.map((g) => ({ held: g.held, ends: g.ends, torsion: g.torsion, arc: g.arc.visible })),
    ghost: () => poses(view.ghosts),
    divergentTick: divergent,
    camera: () => ({ position: v3(view.camera.position), target: v3(controls.target) }),
    seek: (tick) => { setPlaying(false); seek(tick); },
    play: () => setPlaying(true),
    pause: () => setPlaying(false),
    setSpeed: (s) => { speed = s; $('speed').value = String(s); },
    step,
  };
}

start().catch((e) => {
  $('error').textContent = `graspsim view could not show the trace: ${e.message}`;
  $('error').style.display = 'block';
  window.graspsimView = { ready: false, error: String(e) };
});
