// The Live view says what each value is (issue 44, items 1 and 2; docs/dashboard.md "1 Live"):
// - power: with the daemon sending the drive's estimate `pac_W` and no live meter power, the
//   chart is the drive's P_ac, its series named so; the cursor table's rows name P_ac (drive
//   estimate) with the values and P_dcM (meter) with none; the CSV has `pac_W` (equal to the
//   daemon's own telemetry history at the same bench times) and an empty `pdcm_W`, no `pdc_W`;
// - the readout during a sweep of EKF-BASIC/ASPWM: estimator / PWM is the point's (never the
//   manual encoder / capwm), and the disable report of the stop before the sweep is gone while
//   the sweep's point runs the drives.
// Screenshots: ARTIFACT_DIR/live-readout-{1440,1024,390}.png, live-readout-390-power.png.
//
// usage: node live_readout.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import fs from 'node:fs';
import path from 'node:path';
import {
  args, loadPlaywright, launch, check, finish, until, shot, tmpDir, startDaemon, pageOrigin,
  signIn, text, attr, log, rest, tearDown,
} from './harness.mjs';

const { bin, webDir, artifacts } = args();
const pw = loadPlaywright(webDir);

const dataDir = path.join(tmpDir('synbench-web-live-readout-'), 'data');
const daemon = await startDaemon(bin, dataDir, { webDir });
const origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const browser = await launch(pw);
const pageErrors = [];
const readout = (page, k) => text(page, `#readout dd[data-k="${k}"]`);
const status = async () => (await rest(daemon.url, 'GET', '/api/bench/status', token)).json;

try {
  const ctx = await browser.newContext({ viewport: { width: 1440, height: 1000 }, acceptDownloads: true });
  const page = await ctx.newPage();
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(`${origin.url}#/live`);
  await signIn(page, token);

  // ---- the drive running by hand: power drawn and exported as what it is ----
  check((await rest(daemon.url, 'POST', '/api/bench/setpoints', token, { speed_rpm: 600, load_Nm: 1, angle_deg: 50 })).status === 200, 'setpoints 600 rpm, 1 N m');
  check((await rest(daemon.url, 'POST', '/api/bench/enable', token, { enabled: true })).status === 200, 'the bench is enabled by hand');
  const pacUp = await until(async () => { const st = await status(); return st.synrm?.pac_W > 20 ? st.synrm.pac_W : null; }, 20000);
  check(!!pacUp, `the drive reports its power estimate pac_W (${pacUp?.toFixed(1)} W)`);
  await page.waitForTimeout(3000); // a few seconds of load in the buffer
  check(await until(async () => (await readout(page, 'estimator / PWM')) === 'encoder / capwm', 5000),
    `enabled by hand, the readout's estimator / PWM is the manual mode: "${await readout(page, 'estimator / PWM')}"`);

  const head = await text(page, '[data-chart="live-power"] h3');
  check(head.startsWith('Drive power P_ac') && !/^P_dcM/.test(head), `the power chart is titled as the drive's estimate: "${head}"`);
  const ps = await page.evaluate(() => window.synbench.live.cards.get('power').chart.getOption().series
    .map((s) => ({ name: s.name, n: s.data.filter((p) => p[1] != null).length })));
  check(ps[0]?.name === 'P_ac (drive estimate)' && ps[0].n > 20 && ps[1]?.name === 'P_dcM (meter)' && ps[1].n === 0,
    `P_ac (drive estimate) is drawn, P_dcM (meter) has no value without a live meter (${JSON.stringify(ps)})`);
  // The trace's points are the buffer's pac_W at the same times (the buffer may be a sample ahead).
  const trace = await page.evaluate(() => {
    const s = window.synbench.live.cards.get('power').chart.getOption().series.find((x) => x.name === 'P_ac (drive estimate)');
    const byT = new Map(window.synbench.live.buf.map((b) => [b.t_s, b.pac_W]));
    const pts = s.data.filter((p) => p[1] != null);
    return { n: pts.length, same: pts.filter((p) => byT.has(p[0]) && Math.abs(byT.get(p[0]) - p[1]) < 1e-9).length, last: pts.at(-1)?.[1] };
  });
  check(trace.n > 20 && trace.same === trace.n, `the P_ac trace is the telemetry's pac_W (${trace.same} of ${trace.n} points; last ${trace.last?.toFixed(1)} W)`);

  // Cursors on the power chart: the rows name each power.
  await page.selectOption('#scope-span', '10');
  await page.waitForTimeout(400);
  const box = await page.$eval('[data-chart="live-power"] .chart', (e) => { const r = e.getBoundingClientRect(); return { x: r.x, y: r.y, w: r.width, h: r.height }; });
  await page.mouse.click(box.x + box.w * 0.5, box.y + box.h / 2);
  await page.mouse.click(box.x + box.w * 0.8, box.y + box.h / 2);
  const rows = await page.$$eval('#scope-cursors tbody tr', (trs) => trs.map((tr) => [...tr.children].map((c) => c.textContent)));
  const pac = rows.find((r) => r[0] === 'Power P_ac (drive estimate)');
  const pdcm = rows.find((r) => r[0] === 'Power P_dcM (meter)');
  check(!!pac && Number(pac[1]) > 20 && pac[4] === 'W', `the cursor table's P_ac row has the drive's values (${JSON.stringify(pac)})`);
  check(!!pdcm && pdcm[1] === '–' && pdcm[2] === '–', `the P_dcM (meter) row has none (${JSON.stringify(pdcm)})`);
  check(!rows.some((r) => /P_dcM/.test(r[0]) && Number.isFinite(Number(r[1]))), 'no row labelled P_dcM carries the drive\'s estimate');
  await page.click('#scope-clear-cursors');

  const [dl] = await Promise.all([page.waitForEvent('download'), page.click('#scope-csv')]);
  const csv = fs.readFileSync(await dl.path(), 'utf8').trim().split('\n').map((l) => l.split(','));
  const hdr = csv[0];
  check(hdr.includes('pac_W') && hdr.includes('pdcm_W') && !hdr.includes('pdc_W'), `the CSV names the powers pac_W and pdcm_W (${hdr.join(',')})`);
  const ip = hdr.indexOf('pac_W'), im = hdr.indexOf('pdcm_W'), it = hdr.indexOf('t_s');
  const body = csv.slice(1);
  check(body.length > 100 && body.every((r) => r[im] === ''), `pdcm_W is empty in all ${body.length} rows: the daemon sends no live meter power`);
  const hist = (await rest(daemon.url, 'GET', '/api/telemetry/history?span_s=900', token)).json;
  const byT = new Map(hist.t_s.map((t, i) => [Number(t).toFixed(2), hist.channels.pac_W[i]]));
  let matched = 0, equal = 0, loaded = 0;
  for (const r of body) {
    const h = byT.get(Number(r[it]).toFixed(2));
    if (h == null || r[ip] === '') continue;
    matched++;
    if (Math.abs(Number(r[ip]) - h) <= 1e-3 * Math.max(1, Math.abs(h))) equal++;
    if (h > 20) loaded++;
  }
  // (a sample the page took from a REST status read may sit at a history time with another value)
  check(matched > 20 && equal >= 0.95 * matched && loaded > 5,
    `the CSV's pac_W is the daemon's pac_W at the same bench times (${equal} of ${matched} rows equal, ${loaded} under load)`);

  // ---- a stop, then a sweep of EKF-BASIC / ASPWM: the readout shows what the drive runs ----
  check((await rest(daemon.url, 'POST', '/api/bench/enable', token, { enabled: false })).status === 200, 'an ordered stop');
  const dis = await until(async () => { const st = await status(); return st.supervisor?.disable?.confirmed && !st.stopping ? st.supervisor.disable : null; }, 30000);
  check(!!dis, `the daemon confirms both drives disabled (stop at ${dis?.at_s?.toFixed(1)} s)`);
  check(await until(async () => (await readout(page, 'disable')).startsWith('both drives read back disabled'), 10000),
    `after the stop the readout shows its disable: "${await readout(page, 'disable')}"`);
  check(await until(async () => (await readout(page, 'estimator / PWM')).startsWith('encoder / capwm (manual'), 5000),
    `stopped, estimator / PWM says it is the manual mode, for Enable: "${await readout(page, 'estimator / PWM')}"`);

  // The drive's lock flag outlives the run it was raised in (it clears on a setpoint change): the
  // top bar shows it while the SynRM runs, never for a stopped drive (issue 37, item 4). The
  // daemon's own status of the stopped bench, with the flag raised as an EKF run leaves it.
  const stopped = await status();
  const pill = async (st) => { await page.evaluate((x) => window.synbench.setStatus(x), st); return text(page, '#fault-pill'); };
  const stale = await pill({ ...stopped, synrm: { ...stopped.synrm, lock_lost: true, voltage_limited: true } });
  check(stopped.synrm?.state === 'disabled' && stale === 'no fault', `a stopped drive's stale lock-lost flag is not shown: "${stale}" (drive ${stopped.synrm?.state})`);
  const live = await pill({ ...stopped, enabled: true, synrm: { ...stopped.synrm, state: 'running', lock_lost: true } });
  check(live === 'lock lost: on the encoder', `a running drive's lock-lost flag is: "${live}"`);
  await pill(await status());
  const created = await rest(daemon.url, 'POST', '/api/sweeps', token,
    { name: 'ekf readout', dimensions: { speed_rpm: [600], load_Nm: [1], angle_deg: [44, 48, 52, 56, 60, 64],
      configurations: [{ estimator: 'ekf-basic', pwm: 'aspwm' }] }, window_s: 0.5,
      gate: { span_s: 0.3, min_settle_s: 0.3, timeout_s: 4 }, thermal: { enabled: false } });
  check(created.status === 201, `a 6-point EKF-BASIC / ASPWM sweep is created (${created.status})`);
  const id = created.json?.id;
  const started = await rest(daemon.url, 'POST', `/api/sweeps/${id}/start`, token, {});
  check(started.status === 200 || started.status === 202, `and started (${started.status})`);
  const running = await until(async () => { const st = await status(); return st.sweep?.state === 'running' && st.sweep.point && st.synrm?.speed_rpm > 300 ? st : null; }, 30000);
  check(!!running, `the sweep's point runs the drive (${running?.synrm?.speed_rpm?.toFixed(0)} rpm, ${running?.sweep?.point?.estimator}/${running?.sweep?.point?.pwm})`);
  // Sampled while the point runs: every look at the readout agrees with itself.
  const looks = [];
  for (let i = 0; i < 8; i++) {
    const st = await status();
    const dl = await page.$$eval('#readout dd', (dds) => dds.map((d) => [d.dataset.k, d.textContent]));
    if (st.sweep?.state === 'running' && st.sweep.point) looks.push(dl);
    await page.waitForTimeout(400);
  }
  check(looks.length >= 3, `the readout was read ${looks.length} times while a point ran`);
  const est = looks.map((l) => l.find(([k]) => k === 'estimator / PWM')?.[1]);
  check(est.every((e) => e === 'ekf-basic / aspwm (sweep point)'), `estimator / PWM is the sweep point's, every time (${[...new Set(est)].join(' | ')})`);
  check(looks.every((l) => l.every(([, v]) => !/encoder|capwm/.test(v))), 'no readout row names the manual encoder / capwm during the sweep');
  check(looks.every((l) => !l.some(([k]) => k === 'disable')), `the stop's disable report is gone while the sweep runs the drives (${JSON.stringify(looks[0]?.find(([k]) => k === 'disable') || null)})`);
  check(looks.every((l) => /ekf-basic\/aspwm$/.test(l.find(([k]) => k === 'point')?.[1] || '')), 'the point row names ekf-basic/aspwm too');

  await shot(page, artifacts, 'live-readout-1440');
  for (const [w, h] of [[1024, 900], [390, 844]]) {
    await page.setViewportSize({ width: w, height: h });
    await page.waitForTimeout(500);
    if (w === 390) await page.$eval('#readout', (e) => e.scrollIntoView({ block: 'center' }));
    const wide = await page.evaluate(() => document.documentElement.scrollWidth);
    check(wide <= w, `at ${w} px the Live view is no wider than the screen (${wide} px)`);
    await shot(page, artifacts, `live-readout-${w}`);
  }
  await page.$eval('[data-chart="live-power"]', (e) => e.scrollIntoView({ block: 'center' }));
  await shot(page, artifacts, 'live-readout-390-power');
  check((await rest(daemon.url, 'POST', `/api/sweeps/${id}/abort`, token, { reason: 'test done' })).status < 300, 'the sweep is aborted');
  check(pageErrors.length === 0, `no page errors (${pageErrors.join('; ')})`);
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  await tearDown({ browser, origin, daemon });
  log('done');
}
finish();
