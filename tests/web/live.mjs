// The Live view end to end (docs/dashboard.md "1 Live"): during a twin sweep started over REST
// the readout names the sweep and its point, the setpoint traces follow what the sweep commands
// (not the manual 600 rpm), the current-angle chart has data, the manual controls are disabled
// with the reason, and the feed of measured points matches the stored points' efficiency; after
// an E-stop the readout shows the drives' disable read back. The scope: freeze keeps the last x
// while telemetry comes, unfreeze catches up; span; wheel zoom; two cursors with Δt; tooltips
// with units and few digits; CSV of the buffer; a hidden channel stays hidden after a reload.
// The history: a reload fills the charts at once; a daemon restart keeps the old trace (before
// a gap). Screenshots: ARTIFACT_DIR/live-*.png.
//
// usage: node live.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import fs from 'node:fs';
import path from 'node:path';
import {
  args, loadPlaywright, launch, check, finish, until, shot, tmpDir, startDaemon, stopDaemon, pageOrigin,
  signIn, text, attr, log, rest, tearDown,
} from './harness.mjs';

const { bin, webDir, artifacts } = args();
const pw = loadPlaywright(webDir);

const dataDir = path.join(tmpDir('synbench-web-live-'), 'data');
let daemon = await startDaemon(bin, dataDir, { webDir });
const port = daemon.port;
const origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const browser = await launch(pw);
const num = (v) => (v == null || v === '' ? NaN : Number(v));
const lastX = async (page, id) => num(await attr(page, `[data-chart="live-${id}"]`, 'data-last-x'));
const firstX = async (page, id) => num(await attr(page, `[data-chart="live-${id}"]`, 'data-first-x'));
const points = async (page, id) => Number(await attr(page, `[data-chart="live-${id}"]`, 'data-points'));
const drawnLast = (page, id, series) => page.evaluate(([i, s]) => window.synbench.live.drawnLast(i, s), [id, series]);
const readout = (page, k) => text(page, `#readout dd[data-k="${k}"]`);
// Significant digits of each number in a text (leading zeros and the sign aside).
const maxDigits = (t) => Math.max(0, ...(t.match(/\d+(\.\d+)?/g) || []).map((n) => n.replace('.', '').replace(/^0+/, '').length));

try {
  const ctx = await browser.newContext({ viewport: { width: 1400, height: 1000 }, acceptDownloads: true });
  const page = await ctx.newPage();
  await page.goto(`${origin.url}#/live`);
  await signIn(page, token);
  check(await until(async () => (await points(page, 'speed')) > 20, 15000), 'telemetry fills the speed chart');

  // ---- 1. the Live view during a sweep --------------------------------------------------------
  const manual = await rest(daemon.url, 'POST', '/api/bench/setpoints', token, { speed_rpm: 600, load_Nm: 1, angle_deg: 45 });
  check(manual.status === 200, 'manual setpoints 600 rpm, 1 N m are set (bench disabled)');
  const created = await rest(daemon.url, 'POST', '/api/sweeps', token,
    { name: 'live check', dimensions: { speed_rpm: [300], load_Nm: [1.5], angle_deg: [46, 52, 58, 64, 70] }, window_s: 0.5,
      gate: { span_s: 0.3, min_settle_s: 0.3, timeout_s: 4 }, thermal: { enabled: false } });
  check(created.status === 201, 'a twin sweep of 5 points is created over REST');
  const id = created.json.id;
  const started = await rest(daemon.url, 'POST', `/api/sweeps/${id}/start`, token, {});
  check(started.status === 200 || started.status === 202, `the sweep is started over REST (${started.status})`);

  const sweepLine = await until(async () => {
    const t = await readout(page, 'state');
    return new RegExp(`^sweep #${id} running, point [1-5]/5$`).test(t) ? t : null;
  }, 15000);
  check(!!sweepLine, `the readout names the sweep and its point: "${sweepLine || await readout(page, 'state')}"`);
  check(await until(async () => /^300 rpm, 1\.5 N m, \d+°, encoder\/capwm$/.test(await readout(page, 'point')), 10000),
    `the readout shows the point's configuration: "${await readout(page, 'point')}"`);
  const spSpeed = await until(async () => ((await drawnLast(page, 'speed', 'setpoint')) === 300 ? 300 : null), 15000);
  check(spSpeed === 300, `the speed setpoint trace's last value is the point's 300 rpm, not the manual 600 (${await drawnLast(page, 'speed', 'setpoint')})`);
  const st = (await rest(daemon.url, 'GET', '/api/bench/status', token)).json;
  check(st.commanded?.speed_rpm === 300 && st.setpoints.speed_rpm === 600, `the status carries what the bench commands (${JSON.stringify(st.commanded)}) beside the manual setpoints`);
  check(await until(async () => (await points(page, 'angle')) > 10 && [46, 52, 58, 64, 70].includes(await drawnLast(page, 'angle', 'setpoint')), 10000),
    `the current-angle chart θ_i has data, its setpoint a point's angle (${await drawnLast(page, 'angle', 'setpoint')})`);
  check(await until(async () => Number.isFinite(await drawnLast(page, 'angle', 'measured')), 10000), 'θ_i measured from i_d, i_q is drawn');
  const enable = await page.$eval('#btn-enable', (b) => ({ disabled: b.disabled, title: b.title }));
  const apply = await page.$eval('#setpoints-form button[type=submit]', (b) => ({ disabled: b.disabled, title: b.title }));
  check(enable.disabled && enable.title.includes(`sweep #${id}`) && apply.disabled && apply.title.includes('abort'),
    `Enable and Apply are disabled with the reason in their title ("${enable.title}")`);

  const feedRows = await until(async () => {
    const rows = await page.$$eval('#live-points li', (ls) => ls.map((l) => ({ eta: l.dataset.eta, index: Number(l.dataset.index), text: l.textContent })));
    return rows.length >= 2 ? rows : null;
  }, 40000);
  check(!!feedRows, `the feed fills with the measured points (${feedRows?.length})`);
  if (feedRows) {
    const stored = (await rest(daemon.url, 'GET', `/api/sweeps/${id}/points`, token)).json;
    const byIndex = new Map(stored.map((p) => [p.point_index, p]));
    check(feedRows.every((r) => byIndex.has(r.index) && Math.abs(Number(r.eta) - byIndex.get(r.index).efficiency) < 1e-9),
      `each feed row's η is its stored point's efficiency (${feedRows.map((r) => r.eta).join(', ')})`);
    check(feedRows[0].index > feedRows[1].index, 'the newest point is first');
    check(/η \d{1,2}(\.\d+)? ± [\d.]+ %, I_m [\d.]+ ± [\d.]+ A, P_dcM [\d.]+ ± [\d.]+ W, settle [\d.]+ s, (settled|unstable)/.test(feedRows[0].text), `a row reads "${feedRows[0].text}"`);
    // Each value's ± is its stored point's combined standard uncertainty (issue 26), in the order η, I_m, P_dcM.
    const us = await page.$$eval('#live-points li', (ls) => ls.map((l) => ({ index: Number(l.dataset.index), u: [...l.querySelectorAll('.u')].map((e) => Number(e.dataset.u)) })));
    check(us.length >= 2 && us.every((r) => { const p = byIndex.get(r.index); return p && r.u.length === 3 && p.efficiency_u > 0
      && Math.abs(r.u[0] - p.efficiency_u * 100) < 1e-12 && r.u[1] === p.im_u_A && r.u[2] === p.pdcm_u_W; }),
      `each feed row's ± u are its stored point's efficiency_u (in %), im_u_A, pdcm_u_W (${JSON.stringify(us[0]?.u)})`);
    // η in %, as everywhere on the page: the text's value is the stored fraction x 100.
    const shown = Number(/η ([\d.]+) ±/.exec(feedRows[0].text)?.[1]);
    check(Math.abs(shown - byIndex.get(feedRows[0].index).efficiency * 100) < 0.06, `the feed's η is in % (${shown} %)`);
  }
  await shot(page, artifacts, 'live-1-sweep');

  // ---- 4. the disable report after an E-stop --------------------------------------------------
  const es = await rest(daemon.url, 'POST', '/api/bench/estop', token, {});
  check(es.status === 200, 'an E-stop over REST (the sweep faults)');
  check(await until(async () => (await readout(page, 'disable')).startsWith('both drives read back disabled'), 15000),
    `the readout shows the disable read back: "${await readout(page, 'disable')}"`);
  // No sweep runs now, but the E-stop's trip latches: Enable waits for Reset trip, saying so.
  check(await until(async () => page.$eval('#btn-enable', (b) => b.disabled && /tripped/.test(b.title)), 10000),
    `Enable stays disabled while the trip latches, saying why ("${await page.$eval('#btn-enable', (b) => b.title)}")`);
  await shot(page, artifacts, 'live-2-estop');
  check(!!(await until(async () => (await rest(daemon.url, 'POST', '/api/bench/reset', token, {})).status === 200, 15000)), 'reset after the E-stop');
  check(await until(async () => !(await page.$eval('#btn-enable', (b) => b.disabled)), 10000), 'Enable is active again once no sweep runs and the trip is reset');

  // ---- 2. the scope ---------------------------------------------------------------------------
  await page.selectOption('#scope-span', '10');
  check(await until(async () => { const a = await firstX(page, 'speed'); const b = await lastX(page, 'speed'); return b - a <= 10.01 && b - a > 8; }, 5000),
    `span 10 s: the chart shows the last 10 s (${await firstX(page, 'speed')} .. ${await lastX(page, 'speed')})`);
  await page.selectOption('#scope-span', '300');
  check(await until(async () => (await lastX(page, 'speed')) - (await firstX(page, 'speed')) > 12, 5000),
    `span 5 min: the whole buffer is shown (${await firstX(page, 'speed')} .. ${await lastX(page, 'speed')})`);
  await page.selectOption('#scope-span', '10'); // data across the whole width for the hover and the cursors
  await page.waitForTimeout(300);

  await page.click('#scope-freeze');
  const frozenX = await lastX(page, 'speed');
  const bufBefore = await page.evaluate(() => window.synbench.live.buf.length);
  await page.waitForTimeout(2000);
  const bufAfter = await page.evaluate(() => window.synbench.live.buf.length);
  check((await lastX(page, 'speed')) === frozenX && bufAfter > bufBefore + 10,
    `frozen: the chart's last x stays (${frozenX}) while telemetry keeps coming (${bufBefore} -> ${bufAfter} samples)`);

  // Tooltip of a hovered point: units, a few digits.
  const box = await page.$eval('[data-chart="live-speed"] .chart', (e) => { const r = e.getBoundingClientRect(); return { x: r.x, y: r.y, w: r.width, h: r.height }; });
  await page.mouse.move(box.x + box.w * 0.6, box.y + box.h / 2);
  const tip = await until(() => page.$eval('[data-chart="live-speed"] .chart', (el) => [...el.querySelectorAll('div')].map((d) => d.innerText || '').find((t) => t.startsWith('t ='))), 5000);
  check(!!tip && tip.includes('rpm') && maxDigits(tip) <= 5, `the tooltip has units and at most 5 significant digits: "${tip?.replace(/\n/g, ' | ')}"`);
  // Two cursors: Δt and the values at both.
  await page.mouse.click(box.x + box.w * 0.4, box.y + box.h / 2);
  await page.mouse.click(box.x + box.w * 0.7, box.y + box.h / 2);
  const cur = await text(page, '#scope-cursors');
  check(/A .* s, B .* s, Δt [\d.]+ s/.test(cur) && cur.includes('Speed measured') && cur.includes('rpm'), `two cursors read Δt and the channels at both: "${cur.slice(0, 90)}"`);
  // Wheel zoom on the x axis.
  await page.mouse.move(box.x + box.w * 0.5, box.y + box.h / 2);
  await page.mouse.wheel(0, -400);
  const zoom = await until(() => page.evaluate(() => { const z = window.synbench.live.cards.get('speed').chart.getOption().dataZoom[0]; return z.end - z.start < 100 ? z : null; }), 3000);
  check(!!zoom, `the wheel zooms the time axis (${zoom ? `${zoom.start.toFixed(0)}..${zoom.end.toFixed(0)} %` : 'no zoom'})`);
  await shot(page, artifacts, 'live-3-frozen-cursors');
  await page.click('#scope-freeze');
  check(await until(async () => (await lastX(page, 'speed')) > frozenX + 1.5, 5000), `unfrozen: the chart catches up (${frozenX} -> ${await lastX(page, 'speed')})`);

  // CSV of the buffer.
  const buffered = await page.evaluate(() => window.synbench.live.buf.length);
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#scope-csv')]);
  const csv = fs.readFileSync(await download.path(), 'utf8').trim().split('\n');
  const header = 't_s,speed_rpm,cmd_speed_rpm,torque_Nm,cmd_load_Nm,theta_i_deg,cmd_angle_deg,im_A,id_A,iq_A,udc_V,pac_W,pdcm_W,temp_C,pos_err_deg';
  check(csv[0] === header, `the CSV's header has the units: ${csv[0]}`);
  check(csv.length - 1 >= buffered && buffered > 200 && csv.slice(1).every((l) => l.split(',').length === 15 && Number.isFinite(Number(l.split(',')[0]))),
    `the CSV has one row per sample (${csv.length - 1} rows, ${buffered} buffered)`);

  // A hidden channel: not drawn, still hidden after a reload.
  await page.click('.scope-channels summary');
  await page.uncheck('#scope-channels input[data-channel="temp"]');
  check(await until(() => page.$eval('[data-chart="live-temp"]', (e) => e.hidden), 3000), 'the unchecked temperature chart is hidden');

  // ---- 3. the history: a reload fills the charts at once ---------------------------------------
  await page.selectOption('#scope-span', '300');
  await page.reload();
  const tReload = Date.now();
  const full = await until(async () => (await points(page, 'speed')) > 300 ? await points(page, 'speed') : null, 5000, 100);
  check(!!full && Date.now() - tReload < 5000, `after a reload the speed chart has ${full} points at once (${Date.now() - tReload} ms)`);
  check((await lastX(page, 'speed')) - (await firstX(page, 'speed')) > 12, `the refilled trace reaches back before the reload (${await firstX(page, 'speed')} .. ${await lastX(page, 'speed')})`);
  check(await page.$eval('[data-chart="live-temp"]', (e) => e.hidden) && !(await page.$eval('#scope-channels input[data-channel="temp"]', (e) => e.checked)),
    'the hidden channel is still hidden after the reload');
  const bad = await rest(daemon.url, 'GET', '/api/telemetry/history?span_s=abc', token);
  check(bad.status === 400 && bad.json?.error?.message.startsWith('span_s:'), `a bad span_s is refused naming it (${bad.text.slice(0, 80)})`);

  // ---- 3. ... and a daemon restart keeps the old trace -----------------------------------------
  const oldNewest = (await rest(daemon.url, 'GET', '/api/telemetry/history?span_s=1', token)).json.t_s.at(-1);
  check((await stopDaemon(daemon)) === 0, 'the daemon stops on SIGTERM (saving its history)');
  await page.waitForTimeout(1500);
  daemon = await startDaemon(bin, dataDir, { port, webDir });
  const h = (await rest(daemon.url, 'GET', '/api/telemetry/history', token)).json;
  const neg = h.t_s.filter((t) => t < 0).length;
  check(neg > 200, `the restarted daemon serves the old samples before its new clock (${neg} samples, was newest at ${oldNewest} s)`);
  check(await until(async () => (await firstX(page, 'speed')) < -12 && (await lastX(page, 'speed')) >= 0, 30000),
    `the page shows the old trace after the restart (${await firstX(page, 'speed')} .. ${await lastX(page, 'speed')} s)`);
  const gap = await page.evaluate(() => window.synbench.live.cards.get('speed').chart.getOption().series[0].data.some((p) => p[1] == null));
  check(gap, 'the restart shows as a gap in the trace');
  await shot(page, artifacts, 'live-4-after-restart');
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  await tearDown({ browser, origin, daemon });
  log('done');
}
finish();
