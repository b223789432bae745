// The browser test's checks of the page's time series, friction circles, grasp axis, steps and
// views (browser_test.mjs runs them on each scenario's open page). Each compares what the page
// shows (window.graspsimView) with the trace as h5py reads it (trace_dump.py).

// The last row of sorted `ticks` at or before t.
export function rowAt(ticks, t) {
  let r = 0;
  while (r + 1 < ticks.length && ticks[r + 1] <= t) r++;
  return r;
}

// f_n, f_t and mu f_n (N) of a finger's /haptic row h, from the recorded force F, surface point
// SP, HIP and depth: f_n = F . (SP - HIP) / depth, f_t = |F - f_n (SP - HIP) / depth|,
// mu f_n = friction_radius / depth f_n (view/web/series.js documents the same).
export function forcesOf(rec, h) {
  const depth = rec.depth[h];
  if (!(depth > 0)) return { fn: 0, ft: 0, limit: 0 };
  const F = rec.force[h], d = rec.surface_point[h].map((x, k) => x - rec.hip[h][k]);
  const fn = (F[0] * d[0] + F[1] * d[1] + F[2] * d[2]) / depth;
  const t = F.map((x, k) => x - fn * d[k] / depth);
  return { fn, ft: Math.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]), limit: rec.friction_radius[h] / depth * fn };
}

// Within 1e-12 of b, relative (the page and the test evaluate the same formula in float64; the
// margin only spares a reordering of its terms).
const near = (a, b) => Math.abs(a - b) <= 1e-12 * Math.max(1, Math.abs(b));

export async function checkSeries(t, page, trace, name) {
  const { check, hook } = t;
  const ht = trace.haptic_tick, pt = trace.physics_tick;
  // Two ticks: a third of the way into the run and two thirds, each between haptic rows (the
  // value shown is the row before), both in contact in the lift and the mesh grasp.
  for (const frac of [1 / 3, 2 / 3]) {
    const tick = ht[Math.floor(frac * ht.length)] + 3;
    await hook(page, (x) => window.graspsimView.seek(x), tick);
    const s = await hook(page, () => window.graspsimView.series());
    const h = rowAt(ht, tick), p = rowAt(pt, tick);
    let same = true;
    for (const f of s.fingers) {
      const want = forcesOf(trace.fingers[f.name], h);
      const ok = near(f.fn, want.fn) && near(f.ft, want.ft) && near(f.limit, want.limit) && f.state === trace.fingers[f.name].state[h];
      if (!ok) console.log(`  ${f.name} page ${JSON.stringify(f)} trace row ${h} ${JSON.stringify(want)}`);
      same &&= ok;
    }
    for (const b of s.bodies) same &&= b.height === trace.bodies[b.name].position[p][2];
    const f0 = s.fingers[0];
    check(same && f0.fn > 0, `${name}: at tick ${tick} the time series show the trace's /haptic row ${h} ` +
          `(${f0.name} f_n ${f0.fn.toFixed(3)} N, f_t ${f0.ft.toFixed(3)} N, mu f_n ${f0.limit.toFixed(3)} N) and /physics row ${p} (height)`);
  }
  // A click on the force plot at a tick's x moves the timeline there (to the pixel's tick: a
  // pixel spans (last - first) / width ticks).
  const target = ht[Math.floor(ht.length / 2)];
  const box = await hook(page, () => window.graspsimView.plotBox(0));
  const x = await hook(page, (tt) => window.graspsimView.plotX(0, tt), target);
  await page.mouse.click(box.x + x, box.y + box.height / 2);
  const v = await hook(page, () => ({ tick: window.graspsimView.tick(), first: window.graspsimView.first, last: window.graspsimView.last }));
  const perPixel = (v.last - v.first) / (box.width - 44);
  check(Math.abs(v.tick - target) <= perPixel, `${name}: a click on the force plot at tick ${target}'s x moves the timeline to tick ${v.tick} (within ${perPixel.toFixed(1)} ticks, one pixel)`);
}

// The friction circle at a tick in contact: its radius is mu depth with the scenario's mu (0.8
// for the box and the wedge, which the fingers' material (mu 1) leaves in charge: a contact's mu
// is the lower of the two), to the bit, as the engine multiplies them.
export async function checkCircleMuDepth(t, page, trace, name, mu) {
  const { check, hook } = t;
  const ht = trace.haptic_tick, h = Math.floor(ht.length / 2);
  await hook(page, (x) => window.graspsimView.seek(x), ht[h]);
  for (const f of await hook(page, () => window.graspsimView.fingers())) {
    const depth = trace.fingers[f.name].depth[h], state = trace.fingers[f.name].state[h];
    check(state === 1 && f.circle.visible && f.circle.radius === mu * depth,
          `${name}: at tick ${ht[h]} finger ${f.name} sticks and its friction circle's radius ${f.circle.radius} m is mu depth = ${mu} x ${depth} m`);
  }
}

// Step buttons from a physics tick (a tick of every loop): exactly one period of each loop. The
// buttons are clicked in the page (their click handlers), all in one call.
export async function checkSteps(t, page, trace, name, rates) {
  const { check, hook } = t;
  const start = trace.physics_tick[trace.physics_tick.length >> 1];
  const period = { servo: 1, haptic: rates.servo / rates.haptic, physics: rates.servo / rates.physics };
  const buttons = [['sfwd', 'servo', 1], ['hfwd', 'haptic', 1], ['fwd', 'physics', 1],
                   ['sback', 'servo', -1], ['hback', 'haptic', -1], ['back', 'physics', -1]];
  const got = await hook(page, ([ids, from]) => ids.map((id) => {
    window.graspsimView.seek(from);
    document.getElementById(id).click();
    return window.graspsimView.tick();
  }), [buttons.map((b) => b[0]), start]);
  buttons.forEach(([id, loop, dir], k) =>
    check(got[k] === start + dir * period[loop], `${name}: #${id} moves tick ${start} to ${got[k]}, one ${loop} period (${dir * period[loop]})`));
  await hook(page, (x) => window.graspsimView.seek(x), start);
  await page.keyboard.press('Shift+ArrowRight');
  const key = await hook(page, () => window.graspsimView.tick());
  check(key === start + period.haptic, `${name}: Shift+Right moves tick ${start} to ${key}, one haptic period`);
}

// The view buttons put the camera on an axis through the point it looks at.
export async function checkViews(t, page, name) {
  const { check, hook } = t;
  const axes = [['x', [1, 0, 0]], ['y', [0, -1, 0]], ['z', [0, 0, 1]]];
  const cameras = await hook(page, (ids) => ids.map((a) => {
    document.getElementById(`view${a}`).click();
    return window.graspsimView.camera();
  }), axes.map((a) => a[0]));
  axes.forEach(([axis, want], k) => {
    const c = cameras[k], d = c.position.map((x, i) => x - c.target[i]), n = Math.hypot(...d);
    const cos = d.reduce((s, x, i) => s + x * want[i], 0) / n;
    check(cos > 0.9999, `${name}: the '${axis}' view looks along the ${axis} axis (camera direction . axis = ${cos.toFixed(6)})`);
  });
}

// The grasp axis where the grasp rule holds a body (grasp area > 0): between the two touching
// fingers' god-objects, with the recorded torsion; none where it does not.
export async function checkGrasp(t, page, trace, name) {
  const { check, hook } = t;
  const pt = trace.physics_tick;
  // Bodies in the page's order (the model's), which the haptic `body` column indexes.
  const names = await hook(page, () => window.graspsimView.scene.bodies.map((b) => b.name));
  for (const [i, b] of names.entries()) {
    const rec = trace.bodies[b];
    const held = rec.grasp_area.findIndex((a) => a > 0);
    const free = rec.grasp_area.findIndex((a) => a === 0);
    if (free >= 0) {
      await hook(page, (x) => window.graspsimView.seek(x), pt[free]);
      const g = (await hook(page, () => window.graspsimView.grasps()))[i];
      check(!g.held, `${name}: at tick ${pt[free]} ${b} has grasp area 0 and no grasp axis is drawn`);
    }
    if (held < 0) continue;
    await hook(page, (x) => window.graspsimView.seek(x), pt[held]);
    const g = (await hook(page, () => window.graspsimView.grasps()))[i];
    const h = rowAt(trace.haptic_tick, pt[held]);
    const on = Object.keys(trace.fingers).filter((f) => trace.fingers[f].state[h] !== 0 && trace.fingers[f].body[h] === i);
    const ends = on.map((f) => trace.fingers[f].god_object[h]);
    const same = g.held && on.length === 2 && JSON.stringify(g.ends.slice().sort()) === JSON.stringify(ends.slice().sort()) &&
                 g.torsion === rec.torsion[held] && g.arc === (rec.torsion[held] !== 0);
    check(same, `${name}: at tick ${pt[held]} ${b} is held (grasp area ${rec.grasp_area[held].toExponential(3)} m^2): ` +
                `the grasp axis joins ${on.join(' and ')}'s god-objects, torsion ${rec.torsion[held]} N m`);
  }
}

// Contact points: at a physics tick while the body rests on the floor, before any finger touches
// it, the page draws one dot per /contacts row of that tick at the recorded point (exactly:
// float64 passed through), from that tick's rows (not another tick's, which at rest would look the
// same), with an arrow showing the recorded force (to 1e-9 relative: the arrow
// holds it as a unit direction, a quaternion, and a length, whose round trip costs a few ulps),
// floor and body-body points in two colours; and the floor's forces on each body sum to its
// weight m g. Why that holds: the body is at rest (its /physics velocity below 1e-12 m/s, checked),
// so the step changed its momentum by nothing, m dv = (F_floor + m g) h = 0, and the floor carries
// exactly its weight up to the round-off of the step's sums (~1e-15 relative); 1e-9 spares that
// and still catches a point missing (a quarter of the weight) or a row of another tick.
export async function checkContacts(t, page, trace, name) {
  const { check, hook } = t;
  if (!trace.contacts) return check(false, `${name}: the trace has no /contacts (recorded without it)`);
  const pt = trace.physics_tick;
  let touch = trace.haptic_tick.length;   // first haptic row with a finger in contact
  for (const f of Object.values(trace.fingers)) { const i = f.state.findIndex((s) => s !== 0); if (i >= 0) touch = Math.min(touch, i); }
  const row = rowAt(pt, (touch < trace.haptic_tick.length ? trace.haptic_tick[touch] : pt[pt.length - 1]) >> 1);
  const tick = pt[row];
  await hook(page, (x) => window.graspsimView.seek(x), tick);
  const drawn = await hook(page, () => window.graspsimView.contacts());
  const c = trace.contacts, rows = [];
  for (let r = 0; r < c.tick.length; r++) if (c.tick[r] === tick) rows.push(r);
  const close = (a, b) => a.every((x, k) => Math.abs(x - b[k]) <= 1e-9 * Math.max(1e-9, Math.hypot(...b)));
  const same = drawn.length === rows.length && rows.length > 0 && rows.every((r, k) => {
    const d = drawn[k];
    return d.row === r && d.a === c.a[r] && d.b === c.b[r] && d.point.every((x, j) => x === c.point[r][j]) &&
           d.origin.every((x, j) => x === c.point[r][j]) && close(d.force, c.force[r]) &&
           d.kind === (c.a[r] === -2 ? 'floor' : 'body');
  });
  check(same, `${name}: at tick ${tick} the page draws the trace's ${rows.length} /contacts rows: each dot at its point, ` +
              `its arrow its force${same ? '' : ` (drawn ${JSON.stringify(drawn)})`}`);
  // One colour per kind: every floor point's the same, and a body-body point's (where any) another.
  const colours = new Set(drawn.map((d) => `${d.kind} ${d.colour}`)), kinds = new Set(drawn.map((d) => d.kind));
  check(colours.size === kinds.size && new Set(drawn.map((d) => d.colour)).size === kinds.size,
        `${name}: floor and body-body points are drawn in their own colours (${[...colours].join(', ')})`);
  const g = Math.hypot(...trace.gravity);
  for (const [i, b] of Object.keys(trace.bodies).sort().entries()) {
    const index = (await hook(page, () => window.graspsimView.scene.bodies.map((o) => o.name))).indexOf(b);
    const on = drawn.filter((d) => d.a === -2 && d.b === index);
    if (!on.length) continue;
    const sum = [0, 1, 2].map((k) => on.reduce((s, d) => s + c.force[rows[drawn.indexOf(d)]][k], 0));
    const weight = trace.mass[b] * g, v = trace.bodies[b].velocity[row];
    const rest = Math.hypot(...v) < 1e-12;
    check(rest && Math.abs(sum[2] - weight) <= 1e-9 * weight && Math.hypot(sum[0], sum[1]) <= 1e-9 * weight,
          `${name}: at tick ${tick} body ${b} (${i}) at rest (speed ${Math.hypot(...v)} m/s) gets ${JSON.stringify(sum)} N ` +
          `from its ${on.length} floor points, its weight m g = ${weight} N`);
  }
}
