// The dashboard end to end in headless Chromium (docs/dashboard.md): sign in, the live view,
// build and start a small twin sweep in the builder, watch progress reach 100 %, see the
// efficiency map and the MTPA/ME trajectories drawn with data, the results view at 1280x800 and
// tablet size, exports, E-stop by keyboard with the bench stopping, a viewer's read-only page.
// Screenshots: ARTIFACT_DIR/*.png.
//
// usage: node e2e.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import {
  args, loadPlaywright, launch, check, finish, until, shot, tmpDir, startDaemon, pageOrigin,
  signIn, text, attr, log, rest, tearDown,
} from './harness.mjs';

const { bin, webDir, artifacts } = args();
const pw = loadPlaywright(webDir);

const dataDir = path.join(tmpDir('synbench-web-e2e-'), 'data');
// A stored two-configuration sweep (the CLI runs it on virtual time in about a second) for the
// plots a single encoder sweep leaves empty: position error, histograms, deltas.
fs.mkdirSync(dataDir, { recursive: true });
const planFile = path.join(dataDir, '..', 'plan.json');
fs.writeFileSync(planFile, JSON.stringify({ name: 'encoder vs EKF (CLI)', window_s: 0.5,
  dimensions: { speed_rpm: [500, 900], load_Nm: [1, 2, 3], angle_deg: { from: 42, to: 66, step: 4 },
    configurations: [{ estimator: 'encoder', pwm: 'capwm' }, { estimator: 'ekf-basic', pwm: 'aspwm' }] } }));
execFileSync(bin, ['sweep', planFile, '--db', path.join(dataDir, 'synbench.db')], { stdio: 'ignore' });
const daemon = await startDaemon(bin, dataDir, { webDir });
const origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const viewer = execFileSync(bin, ['token', 'create', '--role', 'viewer', '--data-dir', dataDir], { encoding: 'utf8' }).trim();
const browser = await launch(pw);
const pageErrors = [];

try {
  const ctx = await browser.newContext({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
  const page = await ctx.newPage();
  page.on('pageerror', (e) => pageErrors.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') log('console error:', m.text()); });

  // ---- sign in ----
  await page.goto(origin.url);
  check(await page.$('#signin[open]'), 'the sign-in dialog opens on a fresh page');
  check(await page.$('#estop'), 'the E-stop button is on the page');
  await shot(page, artifacts, '01-signin');
  await page.fill('#signin-token', 'sbt_' + '0'.repeat(64));
  await page.click('#signin-submit');
  check(await until(async () => (await text(page, '#signin-error')).includes('Unknown token'), 5000), 'an unknown token is refused with a message');
  await signIn(page, token);
  check((await text(page, '#role-pill')) === 'operator', 'the role pill says operator');
  const conn = await until(async () => { const s = await attr(page, '#conn', 'data-state'); return s === 'connected' ? s : null; }, 10000);
  const connState = conn || (await attr(page, '#conn', 'data-state'));
  check(connState === 'connected' || connState === 'polling', `connection indicator: ${connState}`);
  if (connState !== 'connected') log('note: no WebSocket: the page runs on REST polling');

  // ---- live view ----
  check(await until(async () => Number(await attr(page, '[data-chart="live-speed"]', 'data-points')) > 5, 10000), 'live speed chart draws telemetry');
  check(await until(async () => Number(await attr(page, '[data-chart="live-udc"]', 'data-points')) > 5, 5000), 'live U_dc chart draws telemetry');
  await shot(page, artifacts, '02-live');

  // ---- sweep builder ----
  await page.keyboard.press('2');
  await page.waitForSelector('#view-sweep:not([hidden])');
  await page.selectOption('#b-preset', '');
  await page.fill('#b-name', 'e2e twin sweep');
  const dim = async (key, kind, vals) => {
    const row = `.dimrow[data-dim="${key}"]`;
    await page.selectOption(`${row} [data-role="kind"]`, kind);
    if (kind === 'list') await page.fill(`${row} [data-role="list"]`, vals);
    else for (const [r, v] of Object.entries(vals)) await page.fill(`${row} [data-role="${r}"]`, String(v));
  };
  await dim('speed_rpm', 'list', '300, 600');
  await dim('load_Nm', 'list', '1, 2');
  await dim('angle_deg', 'range', { from: 44, to: 64, step: 10 });
  // one configuration: encoder / CAPWM
  while ((await page.$$('#b-configs .cfgrow')).length > 1) await page.click('#b-configs .cfgrow:last-child button');
  await page.selectOption('#b-configs .cfgrow [data-role="est"]', 'encoder');
  await page.selectOption('#b-configs .cfgrow [data-role="pwm"]', 'capwm');
  await page.fill('#b-window', '0.2');
  await page.fill('#b-span', '0.2');
  await page.fill('#b-settle', '0.2');
  await page.fill('#b-timeout', '3');
  // Gate averaging: the plan's, and one configuration's own (an injecting estimator's, say).
  await page.fill('#b-average', '0.05');
  await page.fill('#b-configs .cfgrow [data-role="avg"]', '0.1');
  await page.uncheck('#b-thermal');
  const sent = await until(async () => {
    const j = JSON.parse((await text(page, '#b-json')) || '{}');
    return j.gate?.average_s === 0.05 && j.dimensions?.configurations?.[0]?.gate_average_s === 0.1 ? j : null;
  }, 5000);
  check(sent, 'the plan carries the gate averaging, the plan\'s and the configuration\'s');
  check(await until(async () => (await attr(page, '#b-estimate', 'data-points')) === '12', 5000),
    `the estimate shows 12 points (${await text(page, '#b-estimate')})`);
  await shot(page, artifacts, '03-builder');
  const started = Date.now();
  await page.click('#b-start');

  // ---- progress to 100 % ----
  // The progress view shows the stored sweep #1 (completed) until the new one is created: on a
  // loaded machine that took longer than a poll, and its 100 % passed for the new sweep's.
  check(await until(async () => (await text(page, '#p-title')).includes('e2e twin sweep'), 10000),
    `the progress view shows the new sweep (${await text(page, '#p-title')})`);
  let midShot = false;
  let etaSeen = null;  // the daemon's ETA (eta_s on the socket): the page computes none of its own
  const done = await until(async () => {
    const pct = Number(await attr(page, '#p-pct', 'data-pct'));
    if (!etaSeen && pct > 0 && pct < 100) etaSeen = (await text(page, '#p-line')).match(/ETA (\d[^·]*)/)?.[1] ?? null;
    if (!midShot && pct >= 25 && pct <= 85 && Number(await attr(page, '[data-chart="p-map"]', 'data-points')) > 0) {
      midShot = true;
      await shot(page, artifacts, '04-progress-filling');
    }
    return pct === 100 && (await text(page, '#p-state')) === 'completed';
  }, 150000, 500);
  check(done, `progress reaches 100 % and the sweep completes (${((Date.now() - started) / 1000).toFixed(0)} s)`);
  check(midShot, 'the efficiency map fills in while the sweep runs');
  check(etaSeen, `the progress line shows the daemon's ETA while the sweep runs (${etaSeen})`);
  check(await until(async () => (await attr(page, '#p-cells', 'data-done')) === '12', 5000), 'every per-point cell is measured');
  const mapPts = await until(async () => { const n = Number(await attr(page, '[data-chart="p-map"]', 'data-points')); return n >= 4 ? n : null; }, 10000);
  check(mapPts >= 4, `the progress efficiency map has a value in every (speed, load) cell (${mapPts})`);
  const trajPts = Number(await attr(page, '[data-chart="p-traj"]', 'data-points'));
  check(trajPts >= 8, `the MTPA/ME trajectories are drawn with data (${trajPts} values)`);
  await shot(page, artifacts, '05-progress-done');

  // ---- results ----
  await page.keyboard.press('3');
  await page.waitForSelector('#view-results:not([hidden])');
  for (const c of ['r-map', 'r-traj', 'r-curve'])
    check(await until(async () => Number(await attr(page, `[data-chart="${c}"]`, 'data-points')) > 0, 10000), `results chart ${c} has data`);
  await shot(page, artifacts, '06-results-1280x800');
  const [csv] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), page.click('#r-csv')]);
  const csvText = fs.readFileSync(await csv.path(), 'utf8');
  check(csvText.split('\n').filter(Boolean).length === 13, 'Points CSV export: header + 12 rows');
  const [png] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), page.click('[data-chart="r-map"] header button')]);
  const pngBytes = fs.readFileSync(await png.path());
  check(pngBytes.length > 2000 && pngBytes.subarray(1, 4).toString() === 'PNG', `PNG export of the efficiency map (${pngBytes.length} bytes)`);
  fs.copyFileSync(await png.path(), path.join(artifacts, 'export-efficiency-map.png'));
  const [json] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), page.click('#r-json')]);
  const analysis = JSON.parse(fs.readFileSync(await json.path(), 'utf8'));
  check(analysis.schema === 'synbench.analysis/1' && analysis.curves.entries.length === 4, 'Analysis JSON export: 4 curves');
  await page.setViewportSize({ width: 820, height: 1180 });
  await page.waitForTimeout(600);
  await shot(page, artifacts, '07-results-tablet-820x1180');
  await page.keyboard.press('2');
  await page.waitForTimeout(400);
  await shot(page, artifacts, '08-sweep-tablet-820x1180');
  await page.keyboard.press('1');
  await page.waitForTimeout(800);
  await shot(page, artifacts, '09-live-tablet-820x1180');
  await page.setViewportSize({ width: 1280, height: 800 });

  // ---- results of a two-configuration sweep (made by the CLI before the daemon started) ----
  await page.keyboard.press('3');
  await page.waitForSelector('#view-results:not([hidden])');
  await page.selectOption('#r-sweep', '1');
  await until(async () => (await text(page, '#r-summary')).startsWith('Sweep #1'), 10000);
  await page.selectOption('#r-config', 'ekf-basic/aspwm');
  for (const c of ['r-map', 'r-traj', 'r-curve', 'r-poserr', 'r-delta', 'r-hist'])
    check(await until(async () => Number(await attr(page, `[data-chart="${c}"]`, 'data-points')) > 0, 10000), `two-configuration sweep: ${c} has data`);
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(artifacts, '10-results-two-configs-full.png'), fullPage: true });
  log('screenshot', path.join(artifacts, '10-results-two-configs-full.png'));

  // ---- E-stop ----
  await page.keyboard.press('1');
  await page.waitForSelector('#view-live:not([hidden])');
  await page.fill('#setpoints-form [name="speed_rpm"]', '600');
  await page.fill('#setpoints-form [name="load_Nm"]', '0.5');
  await page.fill('#setpoints-form [name="angle_deg"]', '50');
  await page.click('#setpoints-form button[type="submit"]');
  await page.click('#btn-enable');
  const spun = await until(async () => {
    const st = await rest(daemon.url, 'GET', '/api/bench/status', token);
    return st.json?.enabled && st.json.synrm?.speed_rpm > 450;
  }, 15000);
  check(spun, 'the bench spins up to 600 rpm from the live view');
  await page.waitForTimeout(1500);
  await shot(page, artifacts, '11-live-running');
  await page.focus('#setpoints-form [name="speed_rpm"]'); // inside a field: Esc twice
  await page.keyboard.press('Escape');
  await page.keyboard.press('Escape');
  check(await until(async () => (await text(page, '#bench-pill')) === 'E-STOPPED', 5000), 'Esc: the bench pill shows E-STOPPED');
  const st = await rest(daemon.url, 'GET', '/api/bench/status', token);
  check(st.json && st.json.enabled === false && st.json.supervisor.phase === 'estopped', 'the daemon reports drives disabled, phase estopped');
  check(st.json && ['disabled', 'faulted'].includes(st.json.synrm.state) && ['disabled', 'faulted'].includes(st.json.load.state),
    `both drives are off (${st.json?.synrm?.state}, ${st.json?.load?.state})`);
  const slowing = await until(async () => {
    const s = await rest(daemon.url, 'GET', '/api/bench/status', token);
    return s.json?.synrm?.speed_rpm < 400;
  }, 15000);
  check(slowing, 'the machine slows down after the E-stop');
  await page.waitForTimeout(1000);
  await shot(page, artifacts, '12-estopped');
  await page.click('#btn-reset');
  check(await until(async () => (await text(page, '#bench-pill')) !== 'E-STOPPED', 5000), 'Reset clears the E-stop latch');

  // ---- history ----
  await page.keyboard.press('4');
  check(await until(async () => (await text(page, '#history tbody tr:first-child td.state')) === 'completed', 5000), 'history lists the sweep as completed');
  await shot(page, artifacts, '13-history');
  check(pageErrors.length === 0, `no uncaught errors on the page (${pageErrors.join('; ')})`);

  // ---- a viewer ----
  const vctx = await browser.newContext({ viewport: { width: 1280, height: 800 } });
  const vpage = await vctx.newPage();
  await vpage.goto(origin.url);
  await signIn(vpage, viewer);
  check((await text(vpage, '#role-pill')).startsWith('viewer'), 'a viewer token shows viewer · read-only');
  check(await vpage.$eval('#estop', (e) => !e.disabled), 'a viewer may press E-stop (every signed-in role may; tests/web/safety.mjs presses it)');
  check(await vpage.$eval('#btn-enable', (e) => e.disabled), 'a viewer cannot enable the bench');
  await shot(vpage, artifacts, '14-viewer');
  await vctx.close();
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  await tearDown({ browser, origin, daemon });
}
finish();
