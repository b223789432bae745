// The page of `graspsim view`: loads /scene.json and /trace.bin (view/README.md, "Data path"),
// draws the trace at a cursor (a servo tick) and runs the timeline. window.graspsimView is the
// hook the browser test reads (view/test).
import { OrbitControls } from 'three/addons/OrbitControls.js';
import { SceneView } from './draw.js';

const $ = (id) => document.getElementById(id);

// Typed-array views of the blob's columns, by name.
function columns(scene, buffer) {
  const out = {};
  for (const c of scene.blob) {
    out[c.name] = c.type === 'i8' ? new Int8Array(buffer, c.offset, c.length)
                                  : new Float64Array(buffer, c.offset, c.length);
  }
  return out;
}

// Index of the last tick <= t in the sorted `ticks` (0 when t precedes them all).
function rowAt(ticks, t) {
  let lo = 0, hi = ticks.length - 1;
  if (hi < 0 || t < ticks[0]) return 0;
  while (lo < hi) {
    const mid = (lo + hi + 1) >> 1;
    if (ticks[mid] <= t) lo = mid; else hi = mid - 1;
  }
  return lo;
}

const slice = (a, row, w) => Array.from(a.subarray(row * w, row * w + w));

async function start() {
  const t0 = performance.now();
  const scene = await fetch('scene.json').then((r) => { if (!r.ok) throw new Error(`scene.json: HTTP ${r.status}`); return r.json(); });
  if (scene.live) { (await import('./live.js')).startLive(scene); return; }   // a running scenario (live.js)
  const buffer = await fetch('trace.bin').then((r) => { if (!r.ok) throw new Error(`trace.bin: HTTP ${r.status}`); return r.arrayBuffer(); });
  const col = columns(scene, buffer);
  const physicsTicks = col.physics_tick, hapticTicks = col.haptic_tick;
  const rate = scene.rates.servo;
  const first = Math.min(physicsTicks[0], hapticTicks.length ? hapticTicks[0] : Infinity);
  const last = physicsTicks[physicsTicks.length - 1];

  $('title').textContent = `graspsim view: ${scene.scenario}`;
  $('trace').textContent = `${scene.trace} (${scene.rates.servo} / ${scene.rates.haptic} / ${scene.rates.physics} Hz, status ${scene.status})`;
  if (scene.note) { $('note').textContent = scene.note; $('note').style.display = 'block'; }

  const view = new SceneView($('stage'), scene);
  const controls = new OrbitControls(view.camera, view.renderer.domElement);

  const scrub = $('scrub');
  scrub.min = first; scrub.max = last; scrub.value = first;
  let cursor = first, playing = false, speed = 1, lastFrame = null, frames = 0;
  let drawn = { tick: null, physicsRow: 0, hapticRow: 0 };

  function draw() {
    const tick = Math.floor(cursor);
    const p = rowAt(physicsTicks, tick), h = rowAt(hapticTicks, tick);
    scene.bodies.forEach((b, i) => view.setBody(i, slice(col[`body/${i}/position`], p, 3), slice(col[`body/${i}/quaternion`], p, 4)));
    scene.fingers.forEach((f, j) => {
      const k = `finger/${j}/`;
      view.setFinger(j, slice(col[k + 'hip'], h, 3), slice(col[k + 'god_object'], h, 3), slice(col[k + 'force'], h, 3),
                     slice(col[k + 'surface_point'], h, 3), col[k + 'friction_radius'][h], col[k + 'state'][h]);
    });
    drawn = { tick, physicsRow: p, hapticRow: h };
    scrub.value = tick;
    $('clock').textContent = `tick ${tick}  t = ${(tick / rate).toFixed(4)} s of ${(last / rate).toFixed(3)} s  (physics row ${p})`;
  }
  function seek(tick) { cursor = Math.max(first, Math.min(last, tick)); draw(); }
  function setPlaying(on) {
    playing = on && cursor < last;
    if (on && cursor >= last) { cursor = first; playing = true; }
    lastFrame = null;
    $('play').textContent = playing ? '||' : '\u25B6';
  }
  // One physics tick back or forward: the /physics row after or before the cursor's tick.
  function step(dir) {
    setPlaying(false);
    const t = Math.floor(cursor);
    let p = rowAt(physicsTicks, t);
    if (dir > 0 && physicsTicks[p] <= t) p++;
    if (dir < 0 && physicsTicks[p] >= t) p--;
    seek(physicsTicks[Math.max(0, Math.min(physicsTicks.length - 1, p))]);
  }

  $('play').onclick = () => setPlaying(!playing);
  $('back').onclick = () => step(-1);
  $('fwd').onclick = () => step(+1);
  $('speed').onchange = (e) => { speed = Number(e.target.value); };
  scrub.oninput = () => { setPlaying(false); seek(Number(scrub.value)); };
  window.addEventListener('keydown', (e) => {
    if (e.key === ' ') { setPlaying(!playing); e.preventDefault(); }
    else if (e.key === 'ArrowRight') step(+1);
    else if (e.key === 'ArrowLeft') step(-1);
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
    bodies: () => view.bodies.map((g) => ({ name: g.name,
      position: [g.position.x, g.position.y, g.position.z],
      quaternion: [g.quaternion.w, g.quaternion.x, g.quaternion.y, g.quaternion.z] })),
    fingers: () => view.fingers.map((f) => ({ name: f.name, state: f.state, colour: f.colour,
      circle: { visible: f.circle.visible, radius: f.circle.scale.x,
                centre: [f.circle.position.x, f.circle.position.y, f.circle.position.z] } })),
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
