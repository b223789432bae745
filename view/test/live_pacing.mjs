// A measurement, not a test: does a paced session keep its servo deadlines with the live view
// open? Runs `graspsim run SCENARIO --device thumb=sim-phantom --pace --duration D` REPS times in
// each of three ways, interleaved: --no-view; --view with no page; --view with headless chromium
// connected and drawing (software WebGL, on the same machine). Prints each run's pacing line
// (overruns, worst lateness, longest gap) and, with a page, the messages it got and the frames it
// drew. Usage: node live_pacing.mjs GRASPSIM_CLI SOURCE_DIR [D=20] [REPS=3] [SCENARIO=two_finger_lift]
import { spawn } from 'node:child_process';
import { mkdtempSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

const [cli, src, d = '20', reps = '3', scenario = 'two_finger_lift'] = process.argv.slice(2);
const tmp = mkdtempSync(join(tmpdir(), 'live_pacing-'));
const { chromium } = await import(join(src, 'view/web/node_modules/playwright-core/index.mjs'));
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium',
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'] });

async function session(mode, k) {
  const args = ['run', join(src, 'scenarios', `${scenario}.lua`), '--device', 'thumb=sim-phantom', '--pace',
                '--duration', d, '--out', join(tmp, `${mode}-${k}.h5`)];
  args.push(...(mode === 'no-view' ? ['--no-view'] : ['--view', '--port', '0']));
  const child = spawn(cli, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  let out = '';
  const exited = new Promise((r) => child.on('exit', r));
  child.stdout.on('data', (x) => { out += x; });
  child.stderr.on('data', (x) => { out += x; });
  let page = null;
  if (mode === 'view+page') {
    while (!/live view\s+http/.test(out)) await new Promise((r) => setTimeout(r, 20));
    page = await browser.newPage({ viewport: { width: 1000, height: 640 } });
    await page.goto(out.match(/live view\s+(http:\/\/127\.0\.0\.1:\d+\/)/)[1]);
  }
  const code = await exited;
  let drawn = '';
  if (page) {
    const v = await page.evaluate(() => ({ m: window.graspsimView.messages(), f: window.graspsimView.frames(),
                                           t: window.graspsimView.tick() }));
    drawn = `; page: ${v.m} messages, ${v.f} frames drawn, last tick ${v.t}`;
    await page.close();
  }
  const pacing = (out.match(/pacing\s+(.*)/) || [, '(no pacing line)'])[1];
  console.log(`${mode.padEnd(10)} #${k} exit ${code}: ${pacing}${drawn}`);
}

for (let k = 1; k <= Number(reps); k++)
  for (const mode of ['no-view', 'view', 'view+page']) await session(mode, k);
await browser.close();
