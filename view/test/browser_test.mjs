// `graspsim view` in a real browser: Debian's chromium, headless, driven by playwright-core.
// It runs two library scenarios, serves each trace, and checks through the page's hook
// (window.graspsimView) what a person would see:
//   - the drawn pose of every body is the trace's (read by h5py, trace_dump.py) at three
//     physics ticks and between two of them, exactly: poses go from the file to three.js as
//     float64 without arithmetic, so any difference is a bug, not round-off;
//   - scrubbing moves the cursor to the tick scrubbed to; playing moves it forward, pausing
//     stops it;
//   - a finger's colour changes at the haptic tick where the trace's contact state changes;
//   - each finger's friction circle lies about the recorded surface point with the recorded
//     radius mu depth;
//   - a screenshot is not blank: background, floor and the body's colour are counted;
//   - the time series at the cursor are the trace's at two ticks, a click on a plot seeks; the
//     friction circle's radius is mu depth; each step button moves one period of its loop; the
//     view buttons look along the axes; the grasp axis is drawn where the grasp rule holds
//     (page_checks.mjs);
//   - the lift, recorded with /contacts: the contact points and forces drawn at a tick before the
//     fingers touch are the trace's rows, and the floor's forces on the resting box sum to its
//     weight (page_checks.mjs);
//   - two runs overlaid (`graspsim view A B`): B's drawn pose is B's trace, the divergent tick
//     marked is the one `graspsim compare A B` reports;
// and that a cut trace is shown up to its last tick with a note, and that bad input (a missing
// file, a file that is not a trace, a port in use) exits 2 with a message naming it.
// Exit 0 pass, 1 fail, 77 skipped (chromium cannot start here).
// Usage: node browser_test.mjs GRASPSIM_CLI SOURCE_DIR TMP_DIR
import { spawn, spawnSync } from 'node:child_process';
import { mkdirSync, rmSync, writeFileSync, statSync, existsSync } from 'node:fs';
import { createServer } from 'node:net';
import { join } from 'node:path';
import { decodePng } from './png.mjs';
import { checkCircleMuDepth, checkContacts, checkGrasp, checkSeries, checkSteps, checkViews } from './page_checks.mjs';

const [cli, src, tmpRoot] = process.argv.slice(2);
const tmp = join(tmpRoot, 'view_browser');
rmSync(tmp, { recursive: true, force: true });
mkdirSync(tmp, { recursive: true });
let failures = 0;
const ok = (what) => console.log(`ok: ${what}`);
const fail = (what) => { console.log(`FAIL: ${what}`); failures++; };
const check = (cond, what) => (cond ? ok(what) : fail(what));

let chromium;
try {
  ({ chromium } = await import(join(src, 'view/web/node_modules/playwright-core/index.mjs')));
} catch (e) {
  console.log(`FAIL: playwright-core is not installed in view/web/node_modules (tools/setup.sh runs npm ci there): ${e.message}`);
  process.exit(1);
}
let browser;
try {
  browser = await chromium.launch({ executablePath: '/usr/bin/chromium', timeout: 60000,
    // WebGL without a GPU: ANGLE on SwiftShader, the software renderer Chromium ships.
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'] });
} catch (e) {
  console.log(`SKIPPED: chromium cannot start here (/usr/bin/chromium, Debian package chromium): ${e.message.split('\n')[0]}`);
  process.exit(77);
}

// A command that should end by itself; one still running after 20 s (a view that serves where it
// should refuse) is killed, and its status (null) fails the check.
function run(args, cwd) {
  const r = spawnSync(cli, args, { encoding: 'utf8', cwd, timeout: 20000, killSignal: 'SIGKILL' });
  return { status: r.status, out: r.stdout + r.stderr };
}
function dump(trace) {
  const r = spawnSync('/usr/bin/python3', [join(src, 'view/test/trace_dump.py'), trace], { encoding: 'utf8', maxBuffer: 1 << 28 });
  if (r.status !== 0) throw new Error(`trace_dump.py ${trace}: ${r.stderr}`);
  return JSON.parse(r.stdout);
}

// Starts `graspsim view TRACE --port 0` and resolves with { child, url } once it prints the URL.
function serve(trace, cwd, ghost) {
  return new Promise((resolve, reject) => {
    const child = spawn(cli, ['view', trace, ...(ghost ? [ghost] : []), '--port', '0'], { stdio: ['ignore', 'pipe', 'pipe'], cwd });
    let out = '';
    const seen = (d) => {
      out += d;
      const m = out.match(/url\s+(http:\/\/127\.0\.0\.1:\d+\/)/);
      if (m) resolve({ child, url: m[1], out });
    };
    child.stdout.on('data', seen);
    child.stderr.on('data', seen);
    child.on('exit', (code) => reject(new Error(`graspsim view ${trace} exited ${code}: ${out}`)));
  });
}
async function stop(child) {
  child.removeAllListeners('exit');   // serve()'s, which reports an early exit
  const done = new Promise((r) => child.on('exit', (code) => r(code)));
  child.kill('SIGINT');
  return done;
}

async function openPage(url) {
  const page = await browser.newPage({ viewport: { width: 1000, height: 640 } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(url);
  await page.waitForFunction(() => window.graspsimView && (window.graspsimView.ready || window.graspsimView.error),
                             null, { timeout: 30000 });
  const err = await page.evaluate(() => window.graspsimView.error);
  if (err) throw new Error(`the page says: ${err}`);
  return { page, errors };
}
const hook = (page, f, arg) => page.evaluate(f, arg);

// Body poses at the cursor against the trace's row `row`, every component exactly.
async function posesEqual(page, trace, tick, row, label) {
  await hook(page, (t) => window.graspsimView.seek(t), tick);
  const drawn = await hook(page, () => ({ tick: window.graspsimView.tick(), bodies: window.graspsimView.bodies() }));
  let same = drawn.tick === tick;
  for (const b of drawn.bodies) {
    const p = trace.bodies[b.name].position[row], q = trace.bodies[b.name].quaternion[row];
    same &&= b.position.every((x, k) => x === p[k]) && b.quaternion.every((x, k) => x === q[k]);
    if (!same) console.log(`  ${b.name} drawn ${JSON.stringify(b)} trace row ${row}: ${JSON.stringify({ p, q })}`);
  }
  check(same, `${label}: at tick ${tick} every body is drawn at the trace's /physics row ${row}`);
}

// The first haptic row where `finger`'s recorded state changes, or -1.
function firstChange(trace, finger) {
  const s = trace.fingers[finger].state;
  for (let i = 1; i < s.length; i++) if (s[i] !== s[i - 1]) return i;
  return -1;
}

// MU: the friction coefficient of the scenario's finger contacts (its param `mu`); CONTROLS: also
// check the step and view buttons (the same page code for every trace: one scenario does), and
// record /contacts and check the contact points drawn.
// Returns the trace as h5py read it.
async function checkScenario(name, scenario, mu, controls) {
  const file = join(tmp, `${name}.h5`);
  const record = controls ? ['--record', 'servo,haptic,physics,devices,contacts'] : [];
  const r = run(['run', join(src, 'scenarios', scenario), '--out', file, '--quiet', ...record]);
  if (r.status !== 0) return fail(`${name}: graspsim run exited ${r.status}: ${r.out}`);
  const trace = dump(file);
  const { child, url } = await serve(file);
  try {
    const t0 = Date.now();
    const { page, errors } = await openPage(url);
    const loadMs = await hook(page, () => window.graspsimView.loadMs);
    ok(`${name}: page ready ${Date.now() - t0} ms after it was asked for, ${loadMs.toFixed(0)} ms of it fetching and ` +
       `drawing the scene (${(statSync(file).size / 1e6).toFixed(1)} MB trace)`);
    const v = await hook(page, () => ({ first: window.graspsimView.first, last: window.graspsimView.last,
                                        physics: window.graspsimView.physicsTicks }));
    const pt = trace.physics_tick, n = pt.length;
    check(JSON.stringify(v.physics) === JSON.stringify(pt), `${name}: the page holds the trace's ${n} /physics ticks`);
    // Three ticks: the first row, the middle, the last; and a tick between two rows, which
    // shows the row before it (a physics row holds the state until the next one).
    for (const row of [0, n >> 1, n - 1]) await posesEqual(page, trace, pt[row], row, name);
    await posesEqual(page, trace, pt[n >> 1] + 1, n >> 1, `${name} (between physics ticks)`);

    // Scrubbing: the slider's input event moves the cursor there; the clock shows its time.
    const to = pt[n >> 2] + 7;
    await page.locator('#scrub').evaluate((el, t) => { el.value = String(t); el.dispatchEvent(new Event('input')); }, to);
    const scrubbed = await hook(page, () => [window.graspsimView.tick(), document.getElementById('clock').textContent]);
    check(scrubbed[0] === to && scrubbed[1].includes(`tick ${to} `), `${name}: scrubbing to tick ${to} shows it (${scrubbed[1]})`);
    // Stepping: one physics tick forward lands on the next /physics row.
    await page.locator('#fwd').click();
    check(await hook(page, () => window.graspsimView.tick()) === pt[(n >> 2) + 1], `${name}: the step button goes to the next physics tick`);

    // Playing from the start at 10x moves the cursor forward; pausing stops it.
    await hook(page, () => { window.graspsimView.seek(window.graspsimView.first); window.graspsimView.setSpeed(10); window.graspsimView.play(); });
    await page.waitForFunction((t) => window.graspsimView.tick() > t, v.first, { timeout: 10000 }).catch(() => {});
    await hook(page, () => window.graspsimView.pause());
    const paused = await hook(page, () => window.graspsimView.tick());
    await page.waitForTimeout(300);
    const later = await hook(page, () => window.graspsimView.tick());
    check(paused > v.first && paused <= v.last && later === paused,
          `${name}: playing moved the cursor from tick ${v.first} to ${paused}; paused, it stays (${later})`);

    // Contact colour: each finger's drawn colour changes at the haptic tick its state does.
    for (const f of Object.keys(trace.fingers)) {
      const i = firstChange(trace, f);
      if (i < 0) { fail(`${name}: finger ${f}'s state never changes in the trace`); continue; }
      const tick = trace.haptic_tick[i], before = trace.fingers[f].state[i - 1], after = trace.fingers[f].state[i];
      const at = async (t) => { await hook(page, (x) => window.graspsimView.seek(x), t);
                                return (await hook(page, () => window.graspsimView.fingers())).find((x) => x.name === f); };
      const a = await at(tick - 1), b = await at(tick);
      check(a.state === before && b.state === after && a.colour !== b.colour,
            `${name}: finger ${f} turns from state ${before} (${a.colour}) to ${after} (${b.colour}) at haptic tick ${tick}`);
    }

    // Friction circles in the middle of the run: about the recorded surface point, of the
    // recorded radius mu depth (float64 passed through, so exactly), shown only in contact.
    {
      const tick = pt[n >> 1];
      await hook(page, (t) => window.graspsimView.seek(t), tick);
      let h = 0;
      while (h + 1 < trace.haptic_tick.length && trace.haptic_tick[h + 1] <= tick) h++;
      for (const f of await hook(page, () => window.graspsimView.fingers())) {
        const rec = trace.fingers[f.name], state = rec.state[h];
        const same = f.circle.visible === (state !== 0) &&
          (state === 0 || (f.circle.radius === rec.friction_radius[h] && f.circle.centre.every((x, k) => x === rec.surface_point[h][k])));
        check(same, `${name}: at tick ${tick} finger ${f.name}'s friction circle is the trace's (state ${state}, ` +
                    `radius ${rec.friction_radius[h]} m about ${JSON.stringify(rec.surface_point[h])})`);
      }
    }

    const t = { check, hook };
    await checkSeries(t, page, trace, name);
    await checkCircleMuDepth(t, page, trace, name, mu);
    if (controls) await checkSteps(t, page, trace, name, await hook(page, () => window.graspsimView.scene.rates));
    await checkGrasp(t, page, trace, name);
    if (controls) await checkContacts(t, page, trace, name);

    // Screenshot in the middle of the run: not blank.
    await hook(page, (t) => window.graspsimView.seek(t), pt[n >> 1]);
    await page.waitForTimeout(200);
    const png = await page.locator('#stage').screenshot();
    writeFileSync(join(tmp, `${name}.png`), png);
    const img = decodePng(png);
    // Not background: anything 24 levels (summed over r, g, b) from #f4f4f2; the floor alone
    // fills most of the view, so > 20% says the scene was drawn. Body-blue: blue above red by
    // 25 levels, which only the bodies' #6b8cc7 is over an area (floor, fingers, arrows and
    // circles are not; the z axis is a 1-pixel line), so > 1% says a body is in view (the box
    // covers about 7%, the wedge about 3%).
    let notBackground = 0, body = 0;
    for (let i = 0; i < img.width * img.height; i++) {
      const r = img.pixels[i * img.channels], g = img.pixels[i * img.channels + 1], b = img.pixels[i * img.channels + 2];
      if (Math.abs(r - 0xf4) + Math.abs(g - 0xf4) + Math.abs(b - 0xf2) > 24) notBackground++;
      if (b > r + 25) body++;
    }
    const total = img.width * img.height;
    check(notBackground > 0.2 * total && body > 0.01 * total,
          `${name}: the screenshot (${img.width} x ${img.height}, ${join(tmp, name + '.png')}) is not blank: ` +
          `${(100 * notBackground / total).toFixed(1)}% not background (> 20%), ${(100 * body / total).toFixed(1)}% body-blue (> 1%)`);
    if (controls) await checkViews(t, page, name);
    check(errors.length === 0, `${name}: no script error in the page${errors.length ? ': ' + errors.join('; ') : ''}`);
    await page.close();
  } finally {
    const code = await stop(child);
    check(code === 0, `${name}: graspsim view stops on SIGINT with exit 0 (got ${code})`);
  }
  return trace;
}

// Two runs overlaid: the lift (A, from checkScenario) and the lift with mu 0.3 (B), where the
// box slips out of the fingers (2 mu N < m g), so B's box ends below A's.
// TA: A as h5py read it.
async function checkOverlay(ta) {
  if (!ta) return fail('overlay: the lift (A) did not run');
  const a = join(tmp, 'two_finger_lift.h5'), b = join(tmp, 'slipping.h5');
  run(['run', join(src, 'scenarios/two_finger_lift.lua'), '--set', 'mu=0.3', '--out', b, '--quiet']);   // its checks fail
  if (!existsSync(b)) return fail('overlay: the run with mu 0.3 wrote no trace');
  const compared = run(['compare', a, b, '--json']);
  const report = JSON.parse(compared.out.slice(compared.out.indexOf('{')));
  const divergent = report.datasets[0].first.tick;
  const tb = dump(b);
  const { child, url } = await serve(a, undefined, b);
  try {
    const { page, errors } = await openPage(url);
    const v = await hook(page, () => ({ tick: window.graspsimView.divergentTick, marker: getComputedStyle(document.getElementById('diverge')).display }));
    check(v.tick === divergent && v.marker === 'block',
          `overlay: the timeline marks tick ${v.tick}, the first divergence graspsim compare reports (${divergent}, ${report.datasets[0].path})`);
    await page.locator('#godiverge').click();
    check(await hook(page, () => window.graspsimView.tick()) === divergent, 'overlay: the divergence button goes to that tick');
    const pt = tb.physics_tick, n = pt.length;
    for (const row of [n >> 1, n - 1]) {
      await hook(page, (x) => window.graspsimView.seek(x), pt[row]);
      const ghost = await hook(page, () => window.graspsimView.ghost());
      let same = true, apart = false;
      for (const g of ghost) {
        const rb = tb.bodies[g.name];
        same &&= g.position.every((x, k) => x === rb.position[row][k]) && g.quaternion.every((x, k) => x === rb.quaternion[row][k]);
        apart ||= g.position[2] !== ta.bodies[g.name].position[row][2];
      }
      check(same && apart, `overlay: at tick ${pt[row]} the ghost is drawn at B's /physics row ${row}, not at A's`);
    }
    check(errors.length === 0, `overlay: no script error in the page${errors.length ? ': ' + errors.join('; ') : ''}`);
    await page.close();
  } finally {
    await stop(child);
  }
}

// A run killed with SIGKILL while writing: its .partial trace, cut at its last flush.
async function cutTrace() {
  const out = join(tmp, 'cut.h5'), partial = out + '.partial';
  const child = spawn(cli, ['run', join(src, 'scenarios/two_finger_lift.lua'), '--duration', '100', '--out', out, '--quiet'],
                      { stdio: 'ignore' });
  const exited = new Promise((r) => child.on('exit', (code, signal) => r(signal ?? code)));
  for (let i = 0; i < 2000; i++) {
    if (existsSync(partial) && statSync(partial).size > 4e6) break;   // about 5 s of 100 s on disk
    await new Promise((r) => setTimeout(r, 5));
  }
  child.kill('SIGKILL');
  const how = await exited;
  return how === 'SIGKILL' && existsSync(partial) ? partial : null;
}

async function checkCut() {
  const file = await cutTrace();
  if (!file) return fail('cut trace: the run ended before it could be killed');
  const trace = dump(file);
  const { child, url, out } = await serve(file);
  try {
    check(/note: .*cut/.test(out), `cut trace: graspsim view says so on stderr`);
    const { page } = await openPage(url);
    const note = await page.locator('#note').textContent();
    const shown = await page.locator('#note').isVisible();
    check(shown && note.includes('cut') && note.includes('last tick'), `cut trace: the page shows the note "${note}"`);
    const last = await hook(page, () => window.graspsimView.last);
    const pt = trace.physics_tick;
    const row = pt.indexOf(last);
    check(row >= 0 && last < 100 * 3000, `cut trace (status ${trace.status}): shown up to tick ${last} of ${pt[pt.length - 1]} recorded, run asked for 300000`);
    if (row >= 0) await posesEqual(page, trace, last, row, 'cut trace, its last tick');
    await page.close();
  } finally {
    await stop(child);
  }
}

// A trace whose scenario does not load where it is viewed (its mesh file named relative to a
// directory that is not there): the bodies are still drawn at the trace's poses, as placeholders,
// and the page says why.
async function checkPlaceholder() {
  const r = run(['run', 'scenarios/mesh_grasp.lua', '--out', join(tmp, 'relative.h5'), '--quiet'], src);
  if (r.status !== 0) return fail(`mesh_grasp from ${src}: graspsim run exited ${r.status}: ${r.out}`);
  const trace = dump(join(tmp, 'relative.h5'));
  const { child, url } = await serve('relative.h5', tmp);   // from tmp, scenarios/meshes/ is not there
  try {
    const { page } = await openPage(url);
    const note = await page.locator('#note').textContent();
    check(/does not load here/.test(note) && /placeholder/.test(note), `a scenario that does not load here: the page says "${note}"`);
    const n = trace.physics_tick.length;
    await posesEqual(page, trace, trace.physics_tick[n - 1], n - 1, 'placeholder bodies');
    await page.close();
  } finally {
    await stop(child);
  }
}

// Bad input: exit 2, a message naming the file or the port, nothing served.
async function checkBadInput() {
  const expect2 = (args, pattern, what) => {
    const r = run(['view', ...args]);
    check(r.status === 2 && pattern.test(r.out), `${what}: exit ${r.status}, "${r.out.trim().split('\n')[0]}"`);
  };
  expect2([join(tmp, 'missing.h5')], /missing\.h5: no such file/, 'a missing file');
  const text = join(tmp, 'not_a_trace.h5');
  writeFileSync(text, 'this is not an HDF5 file\n');
  expect2([text], /not_a_trace\.h5: not a graspsim trace/, 'a file that is not a trace');
  expect2([tmp], /not a regular file/, 'a directory');
  // A trace recorded without the loops the viewer draws from says so, naming its --record.
  const thin = join(tmp, 'physics_only.h5');
  run(['run', join(src, 'scenarios/two_finger_lift.lua'), '--record', 'physics', '--out', thin], tmp);
  expect2([thin], /recorded with --record 'physics:1', without \/haptic/, 'a trace recorded with --record physics');
  const holder = createServer();
  await new Promise((r) => holder.listen(0, '127.0.0.1', r));
  const port = holder.address().port;
  expect2([join(tmp, 'two_finger_lift.h5'), '--port', String(port)], new RegExp(`127\\.0\\.0\\.1:${port} \\(the port is in use`), `port ${port} in use`);
  holder.close();
  // A port another graspsim view serves is in use too (not shared between the two).
  const first = await serve(join(tmp, 'two_finger_lift.h5'), tmp);
  const taken = Number(first.url.match(/:(\d+)\//)[1]);
  expect2([join(tmp, 'two_finger_lift.h5'), '--port', String(taken)], new RegExp(`127\\.0\\.0\\.1:${taken} \\(the port is in use`),
          `port ${taken} served by another graspsim view`);
  await stop(first.child);
  expect2([], /needs a trace file/, 'no trace');
  const lift = join(tmp, 'two_finger_lift.h5');
  expect2([lift, join(tmp, 'missing_b.h5')], /missing_b\.h5: no such file/, 'a second trace that is missing');
  expect2([lift, lift, lift], /at most two traces/, 'three traces');
  const fast = join(tmp, 'physics_100hz.h5');
  run(['run', join(src, 'scenarios/two_finger_lift.lua'), '--set', 'rates.physics=100', '--out', fast, '--quiet']);
  expect2([lift, fast], /cannot compare .* different rates/, 'two traces at different rates');
  const r = run(['compare', lift, lift, '--view', '--atol', '1']);
  check(r.status === 2 && /--view marks the first divergence at tolerance 0/.test(r.out),
        `compare --view with a tolerance: exit ${r.status}, "${r.out.trim().split('\n').pop()}"`);
  const help = run(['view', '--help']);
  check(help.status === 0 && help.out.includes('--port N') && help.out.includes('exit status'), '--help documents the command');
}

try {
  const lift = await checkScenario('two_finger_lift', 'two_finger_lift.lua', 0.8, true);
  await checkScenario('mesh_grasp', 'mesh_grasp.lua', 0.8, false);
  await checkOverlay(lift);
  await checkCut();
  await checkPlaceholder();
  await checkBadInput();
} catch (e) {
  fail(`unexpected: ${e.stack}`);
} finally {
  await browser.close();
}
console.log(failures ? `${failures} check(s) failed` : 'all checks passed');
process.exit(failures ? 1 : 0);
