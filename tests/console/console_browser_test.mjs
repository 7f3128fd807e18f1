// Browser test of the operations console: headless Chromium (Debian's, driven by puppeteer-core)
// against rocksteady-ground serve, which is bridged to a running PIL pair (rocksteady-plant and
// rocksteady-fsw in real time) on an LCM bus in this private network namespace (run_console_test.sh).
// Checks, each with a screenshot in the artefact folder:
//   1. plots receive data: an Open MCT plot of omega_hat_0 has points, and the status view is LIVE;
//   2. a SET_MODE HOLD from the command form is acknowledged (ACCEPTED) and telemetry shows HOLD;
//      a refused command shows the flight's reason; a command sequence run from the browser completes;
//   3. an ERROR event turns red: the plant is stopped, the flight raises sensor_timeout (ERROR) and
//      its row in the events view is red;
//   4. stale telemetry is flagged after the flight software is killed.
// Usage: node console_browser_test.mjs URL ARTEFACT_DIR PLANT_PID FSW_PID
import fs from 'node:fs';
import { createRequire } from 'node:module';

// puppeteer-core is installed with the console's npm packages (ground/console, npm ci).
const require = createRequire(process.env.RS_NODE_MODULES + '/');
const puppeteer = require('puppeteer-core');

const [url, outDir, plantPid, fswPid] = process.argv.slice(2);
if (!url || !outDir || !plantPid || !fswPid) {
  console.error('usage: node console_browser_test.mjs URL ARTEFACT_DIR PLANT_PID FSW_PID');
  process.exit(2);
}
fs.mkdirSync(outDir, { recursive: true });

let failures = 0;
function check(ok, what) {
  console.log((ok ? 'PASS ' : 'FAIL ') + what);
  if (!ok) failures++;
}

const browser = await puppeteer.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--window-size=1400,900']
});
const page = await browser.newPage();
await page.setViewport({ width: 1400, height: 900 });
const pageErrors = [];
page.on('pageerror', (e) => pageErrors.push(String(e)));
page.on('console', (m) => { if (m.type() === 'error') pageErrors.push(m.text() + ' @ ' + JSON.stringify(m.location())); });

async function shot(name) {
  await page.screenshot({ path: outDir + '/' + name + '.png' });
  console.log('screenshot ' + outDir + '/' + name + '.png');
}
async function go(path) {
  await page.goto(url + '#/browse/' + path, { waitUntil: 'domcontentloaded' });
}
async function waitText(selector, re, timeoutMs) {
  try {
    await page.waitForFunction((s, r) => {
      const e = document.querySelector(s);
      return e && new RegExp(r).test(e.textContent);
    }, { timeout: timeoutMs, polling: 200 }, selector, re.source);
    return true;
  } catch (e) {
    return false;
  }
}

try {
  // 1. Status: live telemetry in DETUMBLE; then a plot of omega_hat_0 with data.
  await go('rocksteady:spacecraft/rocksteady:status');
  check(await waitText('#rs-link', /^LIVE/, 30000), 'status view shows LIVE flight telemetry');
  check(await waitText('#rs-tile-mode .rs-tile-value', /DETUMBLE|HOLD/, 10000), 'mode tile shows the flight mode');
  await shot('1-status-live');

  await go('rocksteady:spacecraft/rocksteady:RS_GNC_TLM/rocksteady:RS_GNC_TLM.omega_hat_0');
  // Wait until the plot has drawn points: Open MCT's plot legend shows the newest value, and the
  // telemetry API (the same providers the plot uses) returns history for the plotted window.
  const plotted = await page.waitForFunction(() => {
    const v = document.querySelector('.plot-series-value, .c-plot-legend__value, .js-series-data-loaded');
    const canvas = document.querySelector('canvas');
    return v && canvas && /\d/.test(v.textContent);
  }, { timeout: 30000, polling: 500 }).then(() => true, () => false);
  check(plotted, 'the omega_hat_0 plot shows a value in its legend');
  const history = await page.evaluate(async () => {
    const c = window.rocksteadyClient;
    const rows = await c.history('RS_GNC_TLM', 'omega_hat_0', Date.now() - 600000, Date.now());
    return { n: rows.length, finite: rows.every((r) => Number.isFinite(r.value)) };
  });
  check(history.n >= 5 && history.finite, 'historical telemetry: ' + history.n + ' finite samples of omega_hat_0');
  await new Promise((r) => setTimeout(r, 1500));
  await shot('2-plot-omega');
  // The overlay plot of the three rate components (Open MCT's plot type over our points).
  await go('rocksteady:spacecraft/rocksteady:plot-rate');
  const series = await page.waitForFunction(() => {
    const items = document.querySelectorAll('.plot-legend-item, .c-plot-legend__item');
    return items.length >= 3 && document.querySelector('.js-series-data-loaded') ? items.length : 0;
  }, { timeout: 30000, polling: 500 }).then((h) => h.jsonValue(), () => 0);
  check(series >= 3, 'the body-rate overlay plot has its ' + series + ' series');
  await new Promise((r) => setTimeout(r, 1500));
  await shot('2b-plot-rate-overlay');

  // 2. SET_MODE HOLD from the command form.
  await go('rocksteady:spacecraft/rocksteady:commands');
  await page.waitForSelector('#rs-command option[value="set-mode"]', { timeout: 10000 });
  await page.select('#rs-command', 'set-mode');
  await page.type('#rs-args', 'HOLD');
  await page.click('#rs-send');
  check(await waitText('#rs-command-result', /SET_MODE HOLD \(seq \d+\): ACCEPTED/, 10000),
    'SET_MODE HOLD from the form is acknowledged ACCEPTED');
  // A command the flight refuses shows its reason: TRACK without a trajectory.
  await page.$eval('#rs-args', (e) => { e.value = ''; });
  await page.type('#rs-args', 'TRACK');
  await page.click('#rs-send');
  check(await waitText('#rs-command-result', /SET_MODE TRACK \(seq \d+\): REJECTED: not allowed in this mode/, 10000),
    'SET_MODE TRACK (no trajectory) is rejected with the flight\'s reason');
  await shot('3-command-ack');
  // Bad input is refused on the ground, before anything is sent, with the same message as send.
  const invalid = await page.evaluate(() => window.rocksteadyClient.send('set-mode', ['CRUISE']));
  check(invalid.outcome === 'invalid' && /unknown mode 'CRUISE'/.test(invalid.message) && !invalid.seq,
    'an invalid command is refused before sending: ' + invalid.message);
  await go('rocksteady:spacecraft/rocksteady:status');
  check(await waitText('#rs-tile-mode .rs-tile-value', /^HOLD$/, 10000), 'telemetry shows mode HOLD');

  // A command sequence from the browser: a command, then a wait on telemetry.
  await go('rocksteady:spacecraft/rocksteady:commands');
  await page.waitForSelector('#rs-sequence', { timeout: 10000 });
  await page.$eval('#rs-sequence', (e) => {
    e.value = 'name: browser-check\nsteps:\n  - send: noop\n  - wait: mode == HOLD, timeout 10 s\n';
  });
  await page.click('#rs-run-sequence');
  check(await waitText('#rs-sequence-result', /COMPLETED: 2 steps of 'browser-check'/, 20000),
    'a sequence run from the browser completes');

  // 3. Stop the plant: the flight times out its sensors, goes SAFE and raises an ERROR event.
  process.kill(Number(plantPid), 'SIGTERM');
  await go('rocksteady:spacecraft/rocksteady:events');
  const red = await page.waitForFunction(() => {
    const row = document.querySelector('#rs-events-table tr.rs-sev-ERROR[data-event="sensor_timeout"]');
    return row && getComputedStyle(row).backgroundColor;
  }, { timeout: 30000, polling: 250 }).then((h) => h.jsonValue(), () => null);
  const isRed = (c) => { const m = /rgb\((\d+), (\d+), (\d+)\)/.exec(c || ''); return m && +m[1] > 100 && +m[2] < 60 && +m[3] < 60; };
  check(red !== null && isRed(red), 'sensor_timeout ERROR event row is red (' + red + ')');
  await shot('4-events-error-red');
  await go('rocksteady:spacecraft/rocksteady:status');
  check(await waitText('#rs-tile-mode .rs-tile-value', /^SAFE$/, 10000), 'mode tile shows SAFE');
  const safeRed = await page.$eval('#rs-tile-mode', (e) => e.className.includes('rs-red'));
  check(safeRed, 'SAFE is shown red');

  // 4. Kill the flight software: its telemetry goes stale.
  process.kill(Number(fswPid), 'SIGKILL');
  check(await waitText('#rs-link', /^STALE/, 15000), 'status view flags STALE after the flight software is killed');
  const staleIndicator = await page.evaluate(() => document.body.innerText.includes('STALE · SAFE'));
  check(staleIndicator, 'status-bar indicator shows STALE');
  await shot('5-stale');
} catch (e) {
  console.log('FAIL exception: ' + e);
  failures++;
  await shot('exception').catch(() => {});
}
const realErrors = pageErrors.filter((e) => !/favicon|ResizeObserver/.test(e));
check(realErrors.length === 0, 'no errors in the page (' + realErrors.slice(0, 3).join(' | ') + ')');
await browser.close();
console.log(failures === 0 ? 'console browser test: all checks passed' : 'console browser test: ' + failures + ' failed');
process.exit(failures === 0 ? 0 : 1);
