// The page survives a daemon restart (docs/dashboard.md): while a sweep runs, the daemon is
// stopped with SIGTERM (it aborts the sweep, keeping its points); the page shows it offline; the
// daemon restarts on the same port and data dir, and the page reconnects by itself (indicator back
// to connected, no new sign-in) and shows the restored state: the sweep aborted with its stored
// points in the progress panel and the history, the bench disabled, telemetry flowing; the new
// daemon instance is noticed and the old daemon's events are cleared, with one line "daemon
// restarted" (GET /api/health and the hello carry the instance id). The sweep
// is then continued from the page to completion; a reload keeps the session.
// Screenshots: ARTIFACT_DIR/restart-*.png.
//
// usage: node restart.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import fs from 'node:fs';
import path from 'node:path';
import {
  args, loadPlaywright, launch, check, finish, until, shot, tmpDir, startDaemon, stopDaemon, pageOrigin,
  signIn, text, attr, log, rest, tearDown,
} from './harness.mjs';

const { bin, webDir, artifacts } = args();
const pw = loadPlaywright(webDir);

const dataDir = path.join(tmpDir('synbench-web-restart-'), 'data');
let daemon = await startDaemon(bin, dataDir, { webDir });
const port = daemon.port;
const origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const browser = await launch(pw);
const connected = (page) => until(async () => (await attr(page, '#conn', 'data-state')) === 'connected', 30000);
const live = async (page) => { const s = await attr(page, '#conn', 'data-state'); return s === 'connected' || s === 'polling'; };

try {
  // A sweep running when the daemon stops.
  const created = await rest(daemon.url, 'POST', '/api/sweeps', token,
    { name: 'restart check', dimensions: { speed_rpm: [300, 600], load_Nm: [1], angle_deg: [46, 50, 54, 58] }, window_s: 0.2,
      gate: { span_s: 0.2, min_settle_s: 0.2, timeout_s: 3 }, thermal: { enabled: false } });
  check(created.status === 201, 'a sweep of 8 points is created over REST');
  const id = created.json.id;

  const page = await (await browser.newContext({ viewport: { width: 1280, height: 800 } })).newPage();
  await page.goto(`${origin.url}#/sweep/${id}`);
  await signIn(page, token);
  const viaWs = await connected(page);
  check(viaWs || (await live(page)), `the page is connected (${await attr(page, '#conn', 'data-state')})`);
  await page.click('#p-restart');
  check(await until(async () => Number(await attr(page, '#p-cells', 'data-done')) >= 2, 30000), 'the sweep runs: 2 points measured');
  await shot(page, artifacts, 'restart-1-running');

  const oldInstance = await page.evaluate(() => window.synbench.instance);
  const oldEvents = await page.$$eval('#events li', (lis) => lis.map((li) => li.textContent.trim()));
  check(oldInstance && oldEvents.length > 0, `before the restart: instance ${oldInstance}, ${oldEvents.length} events shown`);
  const code = await stopDaemon(daemon);
  check(code === 0, `SIGTERM: the daemon exits 0 (${code})`);
  const stopped = await rest(daemon.url, 'GET', '/').catch(() => null);
  check(!stopped, 'the daemon is gone');
  check(await until(async () => (await attr(page, '#conn', 'data-state')) === 'offline', 10000), 'the page shows the daemon offline');
  await page.waitForTimeout(3000); // a few seconds down: the page keeps retrying with backoff
  await shot(page, artifacts, 'restart-2-offline');

  daemon = await startDaemon(bin, dataDir, { port, webDir });
  check(daemon.port === port, `the daemon restarts on the same port ${port}`);
  const t0 = Date.now();
  const back = viaWs ? await connected(page) : await until(() => live(page), 30000);
  check(back, `the page reconnects by itself (${((Date.now() - t0) / 1000).toFixed(1)} s, ${await attr(page, '#conn', 'data-state')})`);
  check(!(await page.$('#signin[open]')), 'no new sign-in is needed');
  check((await text(page, '#role-pill')) === 'operator', 'the role is shown again');
  const meta = (await rest(daemon.url, 'GET', `/api/sweeps/${id}`, token)).json;
  check(meta.state === 'aborted' && meta.points_stored >= 2, `the store kept the sweep: ${meta.state}, ${meta.points_stored} points`);
  check(await until(async () => (await text(page, '#p-state')) === 'aborted', 10000), `the progress panel shows the sweep aborted (${await text(page, '#p-state')})`);
  check(await until(async () => Number(await attr(page, '#p-cells', 'data-done')) === meta.points_stored, 10000), 'its stored points are shown');
  check(await until(async () => (await text(page, '#bench-pill')) === 'bench disabled', 10000), `the bench state is restored (${await text(page, '#bench-pill')})`);
  // The new daemon is noticed (its instance id) and the old one's events are gone, with one line.
  check(await until(async () => (await page.evaluate(() => window.synbench.instance)) !== oldInstance, 10000),
    `the page notices the new daemon instance (${await page.evaluate(() => window.synbench.instance)})`);
  check(await until(async () => (await text(page, '#events')).includes('daemon restarted'), 10000), 'the events panel says "daemon restarted"');
  const newEvents = await page.$$eval('#events li', (lis) => lis.map((li) => li.textContent.trim()));
  const stale = newEvents.filter((e) => oldEvents.includes(e));
  check(stale.length === 0 && newEvents.filter((e) => e.includes('daemon restarted')).length === 1,
    `none of the old daemon's events is shown, one restart line (${stale.join('; ') || newEvents.length + ' lines'})`);
  await shot(page, artifacts, 'restart-3-reconnected');
  await page.keyboard.press('1');
  const tBefore = await page.evaluate(() => window.synbench.status?.t_s);
  check(await until(async () => (await page.evaluate(() => window.synbench.status?.t_s)) > tBefore, 5000)
    && Number(await attr(page, '[data-chart="live-speed"]', 'data-points')) > 5, 'telemetry flows again after the restart');
  await page.keyboard.press('4');
  check(await until(async () => (await text(page, '#history tbody')).includes('restart check'), 5000), 'history shows the sweep');
  await shot(page, artifacts, 'restart-4-history');

  // Continue it from the page: it resumes at its first missing point and completes.
  await page.keyboard.press('2');
  await page.click('#p-restart');
  check(await until(async () => (await text(page, '#p-state')) === 'completed' && (await attr(page, '#p-pct', 'data-pct')) === '100', 60000),
    'the sweep continues from the page and completes');
  const pts = (await rest(daemon.url, 'GET', `/api/sweeps/${id}/points`, token)).json;
  check(pts.length === 8 && new Set(pts.map((p) => p.point_index)).size === 8, 'no point measured twice');
  await shot(page, artifacts, 'restart-5-completed');

  await page.reload();
  check(await until(async () => (await text(page, '#role-pill')) === 'operator', 10000), 'a reload keeps the session (token in sessionStorage)');
  check(!(await page.$('#signin[open]')), 'no sign-in dialog after the reload');
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  await tearDown({ browser, origin, daemon });
  log('done');
}
finish();
