// Measures how long `graspsim view TRACE` takes to show a trace (not a test: it times things):
// the server's start (reading and packing the trace, until it prints its URL), then in headless
// chromium the page from navigation until its hook is ready, and the part of that spent
// fetching /scene.json and /trace.bin and building the scene. Median of REPEATS page loads.
// Usage: node view/test/load_time.mjs GRASPSIM_CLI TRACE.h5 [REPEATS]
import { spawn } from 'node:child_process';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const [cli, trace, repeats = '5'] = process.argv.slice(2);
const here = dirname(fileURLToPath(import.meta.url));
const { chromium } = await import(join(here, '../web/node_modules/playwright-core/index.mjs'));
const t0 = Date.now();
const child = spawn(cli, ['view', trace, '--port', '0'], { stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((resolve, reject) => {
  let out = '';
  child.stdout.on('data', (d) => { out += d; const m = out.match(/url\s+(\S+)/); if (m) resolve(m[1]); });
  child.on('exit', (c) => reject(new Error(`graspsim view exited ${c}: ${out}`)));
});
const serverMs = Date.now() - t0;
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium',
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'] });
const ready = [], fetched = [];
for (let i = 0; i < Number(repeats); i++) {
  const page = await browser.newPage({ viewport: { width: 1000, height: 640 } });
  const t = Date.now();
  await page.goto(url);
  await page.waitForFunction(() => window.graspsimView && window.graspsimView.ready, null, { timeout: 60000 });
  ready.push(Date.now() - t);
  fetched.push(await page.evaluate(() => window.graspsimView.loadMs));
  await page.close();
}
await browser.close();
child.removeAllListeners('exit');
child.kill('SIGINT');
const median = (a) => [...a].sort((x, y) => x - y)[a.length >> 1];
console.log(`${trace}: server ready ${serverMs} ms; page ready ${median(ready)} ms (median of ${ready.length}: ${ready.join(' ')}), ` +
            `of which fetch and scene ${median(fetched).toFixed(0)} ms; total ${serverMs + median(ready)} ms`);
