// The sweep builder and progress in headless Chromium (docs/dashboard.md, "2 Sweep"; issue 25 E):
// the estimate asked before sign-in is asked again after it; a preset's description is what it
// loads; a plan above the bench's drive limit is refused at its field (Create disabled) and by
// the daemon at /dimensions/speed_rpm; a small twin sweep's estimate is within 25 % of its real
// duration; the grid cells are keyboard-reachable with their details in a live line; paused shows
// "paused" and no ETA; Abort asks (Esc keeps the sweep running and is no E-stop there, Enter
// aborts with a reason shown in the progress line, the history and the events); a point the sweep
// faulted at shows as a fault; an adaptive sweep's cells are one row per curve without holes; a
// sweep cut by a daemon stop says so. Screenshots: ARTIFACT_DIR/sweep-*.png.
//
// usage: node sweep.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import fs from 'node:fs';
import path from 'node:path';
import {
  args, loadPlaywright, launch, check, finish, until, shot, tmpDir, startDaemon, stopDaemon, pageOrigin,
  signIn, text, attr, log, rest,
} from './harness.mjs';

const { bin, webDir, artifacts } = args();
const pw = loadPlaywright(webDir);

const dataDir = path.join(tmpDir('synbench-web-sweep-'), 'data');
let daemon = await startDaemon(bin, dataDir, { webDir });
const port = daemon.port;
let origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const browser = await launch(pw);
const pageErrors = [];
const quick = (name, extra = {}) => ({ name, window_s: 0.2, gate: { span_s: 0.2, min_settle_s: 0.2, timeout_s: 3 }, thermal: { enabled: false },
  dimensions: { speed_rpm: [300, 600], load_Nm: [1], angle_deg: [46, 54, 62], configurations: [{ estimator: 'encoder', pwm: 'capwm' }] }, ...extra });
const sweepState = async (id) => (await rest(daemon.url, 'GET', `/api/sweeps/${id}`, token)).json;
const ended = (id, ms) => until(async () => ['completed', 'aborted', 'faulted'].includes((await sweepState(id))?.state), ms);
const lineText = (page) => text(page, '#p-line');

try {
  const page = await (await browser.newContext({ viewport: { width: 1280, height: 900 } })).newPage();
  page.on('pageerror', (e) => pageErrors.push(e.message));

  // ---- 1: the estimate asked before sign-in is asked again after it ----
  await page.goto(`${origin.url}#/sweep`);
  check(await until(async () => /token|cannot estimate/i.test(await text(page, '#b-estimate')), 8000),
    `before sign-in the estimate cannot be had: "${await text(page, '#b-estimate')}"`);
  await signIn(page, token);
  check(await until(async () => /\d+ points.*bench time/.test(await text(page, '#b-estimate')), 8000),
    `after sign-in the builder estimates again: "${await text(page, '#b-estimate')}"`);

  // ---- 7: a preset's description is derived from what it loads ----
  for (const [preset, configs] of [['thesis-grid', 8], ['iec-61800-9-2', 1]]) {
    await page.selectOption('#b-preset', preset);
    // The estimate's point count (the daemon's expansion) is the one the description names.
    const matches = async () => { const n = Number(await attr(page, '#b-estimate', 'data-points')); return n > 100 && (await text(page, '#b-preset-desc')).includes(`: ${n} points`); };
    const ok = await until(matches, 15000);
    const desc = await text(page, '#b-preset-desc');
    const pts = await attr(page, '#b-estimate', 'data-points');
    check(ok && desc.includes(`${configs} configuration`),
      `${preset}: the description names ${configs} configuration(s) and the ${pts} points it loads: "${desc}"`);
  }

  // ---- 2: a plan above the drive's limit ----
  const config = (await rest(daemon.url, 'GET', '/api/bench/config', token)).json;
  const over = config.speed_rpm.max + 100;
  await page.selectOption('#b-preset', 'quick-twin-check');
  await page.fill('.dimrow[data-dim="speed_rpm"] [data-role="list"]', `300, ${over}`);
  check(await until(async () => !(await page.$eval('#b-err-speed_rpm', (e) => e.hidden)), 5000)
    && (await text(page, '#b-err-speed_rpm')).includes(String(config.speed_rpm.max)),
  `${over} rpm: the speed field says the bench's limit: "${await text(page, '#b-err-speed_rpm')}"`);
  check(await page.$eval('#b-start', (e) => e.disabled) && await page.$eval('#b-create', (e) => e.disabled), 'Create and start and Create only are disabled');
  check(await page.$eval('.dimrow[data-dim="speed_rpm"] [data-role="list"]', (e) => e.getAttribute('aria-invalid') === 'true'), 'the speed field is marked invalid');
  await shot(page, artifacts, 'sweep-01-over-limit');
  for (const route of ['/api/sweeps/estimate', '/api/sweeps']) {
    const r = await rest(daemon.url, 'POST', route, token, quick('too fast', { dimensions: { speed_rpm: [300, over], load_Nm: [1], angle_deg: [50] } }));
    check(r.status === 400 && r.json?.error?.message.includes('/dimensions/speed_rpm') && r.json.error.message.includes(String(config.speed_rpm.max)),
      `the daemon refuses ${route} at /dimensions/speed_rpm naming the limit: ${r.status} ${r.json?.error?.message}`);
  }
  await page.fill('.dimrow[data-dim="speed_rpm"] [data-role="list"]', '300, 600');
  check(await until(async () => page.$eval('#b-err-speed_rpm', (e) => e.hidden), 5000) && !(await page.$eval('#b-start', (e) => e.disabled)),
    'a plan within the limits clears the error and enables Create');

  // ---- 3: the estimate of a small real-time twin sweep against its duration ----
  check(await until(async () => Number(await attr(page, '#b-estimate', 'data-points')) === 12, 8000), 'the quick preset: 12 points');
  const est = (await rest(daemon.url, 'POST', '/api/sweeps/estimate', token, JSON.parse(await text(page, '#b-json')))).json;
  await page.click('#b-start');
  const first = await until(async () => { const m = /^#(\d+)/.exec(await text(page, '#p-title')); return m ? Number(m[1]) : null; }, 8000);
  check(first, `the sweep #${first} is created and started from the builder`);
  check(await ended(first, 90000), 'the quick sweep ends');
  const s1 = await sweepState(first);
  const took = (Date.parse(s1.finished_at) - Date.parse(s1.started_at)) / 1000;
  check(s1.state === 'completed' && Math.abs(est.duration_s - took) <= 0.25 * took,
    `estimate ${est.duration_s.toFixed(1)} s vs measured ${took.toFixed(1)} s (within 25 %)`);

  // ---- 8: keyboard access to the cells ----
  check(await until(async () => Number(await attr(page, '#p-cells', 'data-done')) === 12, 8000), 'the progress shows 12 measured cells');
  await page.focus('#p-cells .c[tabindex="0"]');
  await page.keyboard.press('ArrowRight');
  await page.keyboard.press('ArrowRight');
  const focused = await page.evaluate(() => document.activeElement?.dataset.key);
  check(focused === 'p2', `ArrowRight moves between cells (focus on ${focused})`);
  check(/^#2 .*rpm.*η/.test(await text(page, '#p-cell-detail')), `the live line tells the focused point: "${await text(page, '#p-cell-detail')}"`);
  check(await page.$eval('#p-cell-detail', (e) => e.getAttribute('aria-live')) === 'polite', 'the detail line is aria-live');
  await page.keyboard.press('End');
  check(await page.evaluate(() => document.activeElement?.dataset.key) === 'p11', 'End goes to the last point');
  check(await page.$$eval('#p-cells .c[tabindex="0"]', (l) => l.length) === 1, 'the cells are one tab stop');
  await shot(page, artifacts, 'sweep-02-cells-keyboard');

  // ---- 4 and 5: paused ETA; abort with a confirmation and a reason ----
  await page.selectOption('#b-preset', 'quick-twin-check');
  await page.fill('#b-name', 'to abort');
  await page.click('#b-start');
  const second = await until(async () => { const m = /^#(\d+)/.exec(await text(page, '#p-title')); return m && Number(m[1]) !== first ? Number(m[1]) : null; }, 8000);
  check(await until(async () => (await sweepState(second)).points_stored >= 1 && /ETA \d/.test(await lineText(page)), 20000), `running: a counting ETA ("${await lineText(page)}")`);
  await page.click('#p-pause');
  check(await until(async () => { const l = await lineText(page); return /paused/.test(l) && !/ETA/.test(l) && (await sweepState(second)).state !== 'completed'; }, 15000),
    `paused: "paused", no ETA ("${await lineText(page)}")`);
  await shot(page, artifacts, 'sweep-03-paused');
  await page.click('#p-resume');
  check(await until(async () => /ETA/.test(await lineText(page)), 8000), `resumed: the ETA is back ("${await lineText(page)}")`);
  await page.click('#p-abort');
  check(await until(async () => page.$eval('#abort-dialog', (d) => d.open), 3000), 'Abort opens a confirmation dialog');
  await page.keyboard.press('Escape');
  check(await until(async () => !(await page.$eval('#abort-dialog', (d) => d.open)), 3000), 'Esc closes the dialog');
  await new Promise((r) => setTimeout(r, 500));
  const st = (await rest(daemon.url, 'GET', '/api/bench/status', token)).json;
  const afterEsc = (await sweepState(second)).state;
  check(!st.supervisor?.trip && st.supervisor?.phase !== 'estopped' && afterEsc !== 'aborted' && afterEsc !== 'faulted',
    `Esc in the dialog neither aborts the sweep nor E-stops the bench (sweep ${afterEsc}, phase ${st.supervisor?.phase})`);
  if ((await sweepState(second)).state !== 'completed') {
    await page.click('#p-abort');
    await page.fill('#abort-reason', 'winding too warm (test)');
    await shot(page, artifacts, 'sweep-04-abort-dialog');
    await page.keyboard.press('Enter');
    check(await ended(second, 15000) && (await sweepState(second)).state === 'aborted', 'Enter in the dialog aborts the sweep');
    check(await until(async () => (await lineText(page)).includes('winding too warm (test)'), 8000), `the progress line shows the reason: "${await lineText(page)}"`);
    const hist = (await rest(daemon.url, 'GET', '/api/sweeps', token)).json.find((s) => s.id === second);
    check(hist?.last_error === 'winding too warm (test)', `the history has the reason: ${hist?.last_error}`);
    check(await until(async () => (await page.$eval('#events', (e) => e.textContent)).includes('winding too warm (test)'), 8000), 'the events show the reason');
    const done2 = (await sweepState(second)).points_stored;
    const cell = await page.$eval(`#p-cells .c[data-key="p${done2}"]`, (e) => ({ cls: e.className, title: e.title })).catch(() => null);
    check(cell && cell.cls.includes('aborted') && !cell.cls.includes('pending') && /aborted/.test(cell.title),
      `the point the sweep was aborted at shows as aborted: ${JSON.stringify(cell)}`);
    await shot(page, artifacts, 'sweep-05-aborted');
  }

  // ---- 2 (cells): a point the sweep faulted at is a fault, never pending ----
  const f = (await rest(daemon.url, 'POST', '/api/sweeps', token, quick('faulted by an E-stop'))).json;
  await rest(daemon.url, 'POST', `/api/sweeps/${f.id}/start`, token, {});
  check(await until(async () => (await sweepState(f.id)).points_stored >= 1, 20000), 'a sweep measures its first point');
  await rest(daemon.url, 'POST', '/api/bench/estop', token, {});
  check(await ended(f.id, 15000) && (await sweepState(f.id)).state === 'faulted', 'the E-stop faults the sweep');
  await page.goto(`${origin.url}#/sweep/${f.id}`);
  const fdone = (await sweepState(f.id)).points_stored;
  const fcell = await until(async () => page.$eval(`#p-cells .c[data-key="p${fdone}"]`, (e) => (e.className.includes('bad') ? { cls: e.className, title: e.title } : null)).catch(() => null), 8000);
  check(fcell && /fault/.test(fcell.title), `the point the sweep faulted at shows as a fault: ${JSON.stringify(fcell)}`);
  check(await page.$$eval('#p-cells .c.active', (l) => l.length) === 0, 'no cell shows in flight on a faulted sweep');
  await shot(page, artifacts, 'sweep-06-faulted');
  check(await until(async () => {
    await rest(daemon.url, 'POST', '/api/bench/reset', token, {});
    return !(await rest(daemon.url, 'GET', '/api/bench/status', token)).json.supervisor?.trip;
  }, 15000, 500), 'the bench resets');

  // ---- 6: an adaptive sweep's cells, one row per curve, no holes ----
  const a = (await rest(daemon.url, 'POST', '/api/sweeps', token, quick('adaptive', { mode: 'adaptive',
    adaptive: { bracket_deg: [40, 70], tolerance_deg: 4, max_evaluations: 6, stencil_deg: 6, angle_u_target_deg: 45 },
    precision: { mode: 'lengthen', pdcm_u_repeat_target_W: 1000, max_window_s: 0.4 },
    dimensions: { speed_rpm: [300, 600], load_Nm: [1], configurations: [{ estimator: 'encoder', pwm: 'capwm' }] } }))).json;
  check(a?.id, `an adaptive sweep is created (${a?.total_points} points at most)`);
  const aEst = (await rest(daemon.url, 'POST', '/api/sweeps/estimate', token, a.plan)).json;
  await rest(daemon.url, 'POST', `/api/sweeps/${a.id}/start`, token, {});
  await page.goto(`${origin.url}#/sweep/${a.id}`);
  check(await ended(a.id, 60000), 'the adaptive sweep ends');
  const sa = await sweepState(a.id);
  const perPoint = aEst.duration_s / aEst.points;
  const aTook = (Date.parse(sa.finished_at) - Date.parse(sa.started_at)) / 1000;
  log(`adaptive: ${sa.points_stored} points in ${aTook.toFixed(1)} s; the estimate per point ${perPoint.toFixed(2)} s x ${sa.points_stored} = ${(perPoint * sa.points_stored).toFixed(1)} s`);
  check(await until(async () => Number(await attr(page, '#p-cells', 'data-done')) === sa.points_stored && (await page.$$('#p-cells .cellrow')).length === 2, 8000),
    'the adaptive cells: one row per curve (2)');
  const cells = await page.$$eval('#p-cells .c', (l) => l.map((e) => e.className));
  check(cells.length === sa.points_stored && !cells.some((c) => /pending|active/.test(c)),
    `no holes: ${cells.length} cells for ${sa.points_stored} points, none pending (${sa.total_points} planned at most)`);
  await page.focus('#p-cells .c[tabindex="0"]');
  await page.keyboard.press('ArrowDown');
  const row = await page.evaluate(() => document.activeElement?.closest('.cellrow')?.getAttribute('aria-label'));
  check(/600 rpm/.test(row || ''), `ArrowDown moves to the next curve's row (${row})`);
  await shot(page, artifacts, 'sweep-07-adaptive');

  // ---- 6b: measure until sure: the Results view tells the sweep's outcome, the builder sets it ----
  const oc = (await rest(daemon.url, 'GET', `/api/sweeps/${a.id}/analysis`, token)).json?.sweep_outcome;
  check(oc?.adaptive && oc?.precision, `the analysis carries the sweep's outcome (${JSON.stringify(oc?.adaptive?.points_used)} points used)`);
  await page.goto(`${origin.url}#/results/${a.id}`);
  const wantOutcome = `Measure until sure: adaptive search: ${oc.adaptive.points_used} points used against ${oc.adaptive.grid_points} on the ${oc.adaptive.grid_step_deg}° grid; `
    + `angle u target 45° met on ${oc.adaptive.curves_target_met} of ${oc.adaptive.curves.length} curves; `
    + `P_dcM u target 1000 W: ${oc.precision.points_missed} of ${oc.precision.points} points above it.`;
  check(await until(async () => (await text(page, '#r-outcome')) === wantOutcome, 15000),
    `the Results view tells the outcome from the analysis: "${await text(page, '#r-outcome')}"`);
  check(oc.adaptive.points_used === sa.points_stored && oc.adaptive.grid_points === 2 * 16 && oc.precision.points === sa.points_stored,
    `the outcome counts the stored points against the 2° grid over 40..70 (16 angles per curve): ${oc.adaptive.points_used} of ${oc.adaptive.grid_points}`);
  await page.goto(`${origin.url}#/sweep`);
  await page.check('input[name="b-mode"][value="adaptive"]');
  await page.fill('#b-angle-u', '0.5');
  await page.fill('#b-pdcm-u', '0.05');
  await page.fill('#b-max-window', '4');
  const built = JSON.parse(await text(page, '#b-json'));
  check(built.adaptive?.angle_u_target_deg === 0.5 && JSON.stringify(built.precision) === JSON.stringify({ mode: 'lengthen', pdcm_u_repeat_target_W: 0.05, max_window_s: 4 }),
    `the builder's targets reach the plan (${JSON.stringify({ angle_u_target_deg: built.adaptive?.angle_u_target_deg, precision: built.precision })})`);
  const builtEst = (await rest(daemon.url, "POST", "/api/sweeps/estimate", token, built)).json;
  check(builtEst?.upper_bound === true && builtEst.precision_extra_s > 0, `the daemon accepts the built plan and estimates an upper bound (${builtEst?.precision_extra_s} s for lengthening)`);
  await page.fill('#b-pdcm-u', '');
  await page.fill('#b-angle-u', '');
  const cleared = JSON.parse(await text(page, '#b-json'));
  check(!('precision' in cleared) && !('angle_u_target_deg' in (cleared.adaptive || {})), 'empty targets leave them out of the plan');
  await page.check('input[name="b-mode"][value="grid"]');

  // ---- 5: a sweep cut by a daemon stop says why ----
  const r = (await rest(daemon.url, 'POST', '/api/sweeps', token, quick('cut by a stop'))).json;
  await rest(daemon.url, 'POST', `/api/sweeps/${r.id}/start`, token, {});
  check(await until(async () => (await sweepState(r.id)).points_stored >= 1, 20000), 'a sweep runs when the daemon stops');
  await stopDaemon(daemon);
  daemon = await startDaemon(bin, dataDir, { port, webDir });
  const sr = await sweepState(r.id);
  check(sr.state === 'aborted' && /^daemon stopped at \d{4}-\d\d-\d\dT/.test(sr.last_error || ''), `after the restart it says why: ${sr.state}, "${sr.last_error}"`);
  await page.goto(`${origin.url}#/sweep/${r.id}`);
  check(await until(async () => (await lineText(page)).includes('daemon stopped at'), 20000), `the progress line too: "${await lineText(page)}"`);
  await shot(page, artifacts, 'sweep-08-daemon-stopped');
  check(pageErrors.length === 0, `no page errors (${pageErrors.join('; ')})`);
} finally {
  await browser.close();
  await origin.stop();
  await stopDaemon(daemon);
}
finish();
