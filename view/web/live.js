// The page given a live run (`graspsim run ... --view`, view/README.md "Live"): the scene from
// /scene.json, then /live, a Server-Sent Events stream of the run's newest snapshot (about 60 a
// second). Each message is drawn at the next frame; the timeline shows the run's tick. When the
// run ends the stream says how, and which trace it wrote. window.graspsimView is the test hook.
import { OrbitControls } from 'three/addons/OrbitControls.js';
import { SceneView } from './draw.js';

const $ = (id) => document.getElementById(id);

export function startLive(scene) {
  const rate = scene.rates.servo;
  $('title').textContent = `graspsim live: ${scene.scenario}`;
  $('trace').textContent = `${scene.trace} (${scene.rates.servo} / ${scene.rates.haptic} / ${scene.rates.physics} Hz)`;
  for (const id of ['back', 'play', 'fwd', 'speed', 'scrub']) $(id).style.display = 'none';
  const note = (text) => { $('note').textContent = text; $('note').style.display = 'block'; };

  const view = new SceneView($('stage'), scene);
  const controls = new OrbitControls(view.camera, view.renderer.domElement);
  let latest = null, drawn = null, framed = false, messages = 0, frames = 0, ended = null;

  function draw(s) {
    s.bodies.forEach((b, i) => view.setBody(i, b.slice(0, 3), b.slice(3, 7)));
    s.fingers.forEach((f, j) => view.setFinger(j, f.hip, f.god_object, f.force, f.surface_point, f.friction_radius, f.state));
    drawn = s;
    $('clock').textContent = `live: tick ${s.tick}  t = ${(s.tick / rate).toFixed(4)} s of ${scene.duration.toFixed(3)} s`;
    if (!framed) { controls.target.copy(view.frame()); framed = true; }
  }

  const source = new EventSource('live');
  source.onmessage = (e) => { latest = JSON.parse(e.data); messages++; };
  source.addEventListener('end', (e) => {
    // The run's last snapshot came just before; drawn now, not at the next frame, so that what
    // the page shows once it says the run ended is that last tick.
    if (latest && latest !== drawn) draw(latest);
    ended = JSON.parse(e.data);
    source.close();
    const trace = ended.trace ? ` Its trace: ${ended.trace} (\`graspsim view ${ended.trace}\` shows it with the timeline).` : ' No trace was written.';
    note(`The run ended (${ended.status}); shown at its last tick.${trace}`);
  });
  source.onerror = () => {
    if (ended) return;
    // The server went before saying the run ended (killed), or is not there yet: EventSource
    // retries by itself.
    note('The live run is not answering (it was stopped, or the connection is lost); retrying.');
  };
  source.onopen = () => { if (!ended) $('note').style.display = 'none'; };

  function frame() {
    if (latest && latest !== drawn) draw(latest);
    controls.update();
    view.render();
    frames++;
    requestAnimationFrame(frame);
  }
  requestAnimationFrame(frame);

  window.graspsimView = {
    ready: true,
    live: true,
    scene,
    tick: () => (drawn ? drawn.tick : null),
    physicsTick: () => (drawn ? drawn.physics_tick : null),   // the servo tick the drawn poses are from
    messages: () => messages,
    frames: () => frames,
    ended: () => ended,                                      // null while running; then { status, trace }
    note: () => ($('note').style.display === 'none' ? '' : $('note').textContent),
    bodies: () => view.bodies.map((g) => ({ name: g.name,
      position: [g.position.x, g.position.y, g.position.z],
      quaternion: [g.quaternion.w, g.quaternion.x, g.quaternion.y, g.quaternion.z] })),
    fingers: () => view.fingers.map((f) => ({ name: f.name, state: f.state, colour: f.colour })),
  };
}
