// Uncertainty on the Results view in headless Chromium (issue 26, docs/dashboard.md "3 Results"):
// a small twin sweep run from REST (2 speeds x 2 loads x 5 angles, two configurations, short
// windows) and one of the reference stored by the CLI to compare with; the error bars of the MTPA/ME trajectories, the
// I_m/P_dcM curves, the efficiency against load and the deltas have half-lengths 2u of the REST
// analysis / points; insignificant deltas are faded and say "not significant"; the tables' +/- u
// columns and ME - MTPA significance equal the analysis; the efficiency map's tooltip has
// eta +/- u and its "map of u" toggle draws u; the comparison carries u(diff) = sqrt(uA^2 + uB^2)
// of the point-to-point parts and marks insignificant differences; and a sweep from before the
// record had u (stored by the CLI, its u columns NULL as the schema-8 migration leaves old rows)
// shows "no uncertainty stored", no bars, nothing "significant".
//
// usage: node uncertainty.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import {
  args, loadPlaywright, launch, check, finish, until, shot, tmpDir, startDaemon, pageOrigin,
  signIn, text, log, rest, tearDown,
} from './harness.mjs';

const { bin, webDir, artifacts } = args();
const pw = loadPlaywright(webDir);

const dataDir = path.join(tmpDir('synbench-web-unc-'), 'data');
fs.mkdirSync(dataDir, { recursive: true });
const db = path.join(dataDir, 'synbench.db');
const enc = { estimator: 'encoder', pwm: 'capwm' };
const configurations = [enc, { estimator: 'encoder', pwm: 'aspwm' }];
const plan = (name, configs) => ({ name, window_s: 0.2, gate: { span_s: 0.2, min_settle_s: 0.2, timeout_s: 3 }, thermal: { enabled: false },
  dimensions: { speed_rpm: [300, 600], load_Nm: [1, 2], angle_deg: { from: 44, to: 64, step: 5 }, configurations: configs } });

// Sweep #1, "from before": stored by the CLI, then its points' u cleared, as rows of a database
// made before schema version 8 are after the migration (db/migrations.cpp adds NULL columns).
// Sweep #2: the reference configuration again, by the CLI, to compare with.
const U_COLS = ['im_u_A', 'pdcm_u_W', 'pdcg_u_W', 'pm_u_W', 'efficiency_u', 'im_u_repeat_A', 'pdcm_u_repeat_W', 'efficiency_u_repeat'];
for (const [name, file] of [['from before the uncertainty', 'old.json'], ['repeat of the reference', 'repeat.json']]) {
  fs.writeFileSync(path.join(dataDir, '..', file), JSON.stringify(plan(name, [enc])));
  execFileSync(bin, ['sweep', path.join(dataDir, '..', file), '--db', db], { stdio: 'ignore' });
}
execFileSync('sqlite3', [db, `UPDATE points SET ${U_COLS.map((c) => `${c} = NULL`).join(', ')} WHERE sweep_id = 1;`]);
const daemon = await startDaemon(bin, dataDir, { webDir });
const origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const browser = await launch(pw);
const pageErrors = [];

const get = async (p) => (await rest(daemon.url, 'GET', p, token)).json;
const known = (u) => typeof u === 'number' && Number.isFinite(u);
const near = (a, b) => Math.abs(a - b) <= 1e-9 * Math.max(1, Math.abs(a), Math.abs(b));
// two significant digits, as the page prints a u
const fu = (u) => { if (!known(u)) return '–'; if (u === 0) return '0'; return u.toFixed(Math.min(Math.max(0, 1 - Math.floor(Math.log10(u))), 8)); };
const f = (v, d) => (v == null || !Number.isFinite(v) ? '–' : v.toFixed(d));
const rows = (page, sel) => page.$$eval(`${sel} tbody tr`, (trs) => trs.map((tr) => [...tr.children].map((c) => c.textContent.trim())));
const heads = (page, sel) => page.$$eval(`${sel} thead th`, (ths) => ths.map((c) => c.textContent.trim()));
const series = (page, card) => page.evaluate((k) => window.synbench.resultsView.cards[k].option.series
  .map((s) => ({ name: s.name, type: s.type, bars: !!s.errorBars, data: s.data })), card);
// [x, lo, hi, u, y] of every bar of a series named name
const barsOf = (ss, name) => ss.find((s) => s.bars && s.name === name)?.data || [];

async function runSweep(p) {
  const c = (await rest(daemon.url, 'POST', '/api/sweeps', token, p)).json;
  await rest(daemon.url, 'POST', `/api/sweeps/${c.id}/start`, token, {});
  const done = await until(async () => ['completed', 'aborted', 'faulted'].includes((await get(`/api/sweeps/${c.id}`))?.state), 60000, 500);
  return { id: c.id, state: done && (await get(`/api/sweeps/${c.id}`)).state };
}

try {
  const s2 = await runSweep(plan('with uncertainty', configurations));
  const s3 = { id: 2 };
  check(s2.state === 'completed' && s2.id === 3, `the twin sweep from REST completed (#${s2.id} ${s2.state})`);
  const A = await get(`/api/sweeps/${s2.id}/analysis`);
  const P = await get(`/api/sweeps/${s2.id}/points`);
  const B = await get(`/api/sweeps/${s3.id}/analysis`);
  const withU = P.filter((p) => known(p.pdcm_u_W) && known(p.im_u_A)).length;
  check(P.length === 40 && withU === 40, `sweep #${s2.id}: 40 points, every one with im_u_A and pdcm_u_W (${withU})`);
  const curves = A.curves.entries;
  const angleU = curves.filter((c) => known(c.mtpa_angle_u_deg) && known(c.me_angle_u_deg)).length;
  check(curves.length === 8 && angleU >= 6, `the analysis has 8 curves, ${angleU} with mtpa_angle_u_deg and me_angle_u_deg (null only for an optimum at an edge)`);

  const ctx = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await ctx.newPage();
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(origin.url);
  await signIn(page, token);
  await page.goto(`${origin.url}#/results/${s2.id}`);
  if (await page.$('#signin[open]')) await signIn(page, token);
  check(await until(async () => (await text(page, '#r-summary')).startsWith(`Sweep #${s2.id}`), 15000), 'the results view shows the sweep');
  await page.selectOption('#r-config', 'encoder/capwm');
  await page.waitForTimeout(300);

  // ---- 1. error bars: half-length 2u of the REST analysis ----
  const traj = await series(page, 'traj');
  let n = 0, want = 0, bad = [];
  for (const c of curves.filter((x) => x.estimator === 'encoder' && x.pwm === 'capwm')) {
    for (const [o, uk] of [['MTPA', 'mtpa_angle_u_deg'], ['ME', 'me_angle_u_deg']]) {
      const b = barsOf(traj, `±2u ${o} ${c.speed_rpm} rpm`).find((d) => d[0] === c.load_Nm);
      const y = c[o.toLowerCase()].angle_deg;
      if (!known(c[uk])) { if (b) bad.push(`${o} ${c.speed_rpm}/${c.load_Nm}: a bar without u`); continue; }
      want++;
      if (b && near((b[2] - b[1]) / 2, 2 * c[uk]) && near((b[1] + b[2]) / 2, y)) n++; else bad.push(`${o} ${c.speed_rpm}/${c.load_Nm}: ${b}`);
    }
  }
  check(n >= 4 && n === want && !bad.length, `trajectory chart: ${n} error bars, half-length 2 x mtpa/me_angle_u_deg about the angle, none where u is null (${bad.slice(0, 2)})`);
  const trajNote = await page.evaluate(() => [].concat(window.synbench.resultsView.cards.traj.option.title).map((t) => t?.text).join(' '));
  check(trajNote.includes('±2u, 95 %'), `the trajectory chart says what its bars are: "${trajNote}"`);

  const speed = Number(await page.$eval('#r-speed', (e) => e.value));
  const load = Number(await page.$eval('#r-load', (e) => e.value));
  const curve = await series(page, 'curve');
  const at = P.filter((p) => p.speed_rpm === speed && p.load_Nm === load && p.estimator === 'encoder' && p.pwm === 'capwm');
  const sample = at.filter((_, k) => k % 2 === 0);
  const imBars = barsOf(curve, '±2u I_m encoder / capwm');
  const pdBars = barsOf(curve, '±2u P_dcM encoder / capwm');
  const okCurve = sample.filter((p) => {
    const bi = imBars.find((d) => d[0] === p.angle_deg), bp = pdBars.find((d) => d[0] === p.angle_deg);
    return bi && bp && near((bi[2] - bi[1]) / 2, 2 * p.im_u_A) && near((bp[2] - bp[1]) / 2, 2 * p.pdcm_u_W);
  }).length;
  check(sample.length >= 3 && okCurve === sample.length, `curve chart at ${speed} rpm, ${load} N m: I_m and P_dcM bars are 2 x im_u_A, pdcm_u_W of the points (${okCurve} of ${sample.length} sampled)`);

  const em = A.efficiency_map.entries.find((e) => e.estimator === 'encoder' && e.pwm === 'capwm');
  const eta = await series(page, 'eta');
  let okEta = 0;
  em.speeds_rpm.forEach((s, i) => em.loads_Nm.forEach((l, j) => {
    const b = barsOf(eta, `±2u η ${s} rpm`).find((d) => d[0] === l);
    if (b && known(em.efficiency_u?.[i]?.[j]) && near((b[2] - b[1]) / 2, 2 * em.efficiency_u[i][j] * 100)) okEta++;
  }));
  check(okEta === 4, `efficiency-against-load chart: 4 bars of 2 x efficiency_u (in %) of the map (${okEta})`);

  // ---- 2. deltas: insignificant ones faded and "not significant" ----
  const delta = await series(page, 'delta');
  const des = A.deltas.entries;
  const dbars = delta.filter((s) => s.type === 'bar');
  const flat = dbars.flatMap((s, k) => s.data.filter(Boolean).map((d) => ({ ...d, axis: k % 2 })));
  const faded = flat.filter((d) => d.itemStyle?.opacity < 1);
  const insignificant = des.flatMap((d) => [d.mtpa?.delta_im_significant, d.me?.delta_pdcm_significant]).filter((s) => s === false).length;
  check(flat.length === 8 && faded.length === insignificant && flat.every((d) => (d.significant === false) === (d.itemStyle?.opacity < 1)),
    `delta chart: ${faded.length} faded bars, exactly those the analysis calls not significant (${insignificant} of ${flat.length})`);
  const dEb = delta.filter((s) => s.bars).flatMap((s) => s.data);
  const wantDu = des.flatMap((d) => [d.mtpa.delta_im_u_A, d.me.delta_pdcm_u_W]).filter(known).sort((p, q) => p - q);
  check(dEb.length === wantDu.length && dEb.map((d) => (d[2] - d[1]) / 4).sort((p, q) => p - q).every((u, k) => near(u, wantDu[k])), `delta chart: error bars of 2 x delta_im_u_A / delta_pdcm_u_W (${dEb.length})`);
  check(insignificant > 0, `the twin sweep has an insignificant delta to show (${insignificant})`);
  if (insignificant > 0) {
    const tip = await page.evaluate(() => {
      const v = window.synbench.resultsView.cards.delta;
      const si = v.option.series.findIndex((s) => s.type === 'bar' && s.data.some((d) => d?.significant === false));
      const di = v.option.series[si].data.findIndex((d) => d?.significant === false);
      v.chart.dispatchAction({ type: 'showTip', seriesIndex: si, dataIndex: di });
      return new Promise((r) => setTimeout(() => r([...v.el.querySelectorAll('div')].map((d) => d.textContent).join(' ')), 300));
    });
    check(/not significant at 95 %/.test(tip) && /± [0-9.]+ [AW] \(k=1\)/.test(tip), `the faded bar's tooltip says "not significant at 95 %" with value ± u (${tip.slice(0, 160)})`);
    const dNote = await page.evaluate(() => window.synbench.resultsView.cards.delta.option.title.map((t) => t.text).join(' '));
    check(dNote.includes('not significant at 95 %'), `the delta chart's legend note explains the faded bars: "${dNote}"`);
  }
  await page.$eval('[data-chart="r-delta"]', (e) => e.scrollIntoView());
  await shot(page, artifacts, 'unc-1-charts');

  // ---- 3. the efficiency map: tooltip with u, the map of u ----
  const mapTip = await page.evaluate(() => {
    const v = window.synbench.resultsView.cards.map;
    v.chart.dispatchAction({ type: 'showTip', seriesIndex: 0, dataIndex: 0 });
    return new Promise((r) => setTimeout(() => r([...v.el.querySelectorAll('div')].map((d) => d.textContent).join(' ')), 300));
  });
  const u00 = em.efficiency_u[0][0] * 100;
  check(mapTip.includes(`± ${fu(u00)} % (k=1)`), `the map's cell tooltip gives η ± u: "${mapTip.slice(0, 120)}" (u ${fu(u00)} %)`);
  await page.click('#r-map-u');
  const uMap = await page.evaluate(() => window.synbench.resultsView.cards.map.option.series[0].data.map((d) => d.value));
  const wantU = em.speeds_rpm.flatMap((s, i) => em.loads_Nm.map((l, j) => [i, j, Number((em.efficiency_u[i][j] * 100).toFixed(4))]));
  check(uMap.length === 4 && JSON.stringify(uMap) === JSON.stringify(wantU) && await page.$eval('#r-map-u', (e) => e.getAttribute('aria-pressed')) === 'true',
    `"map of u" draws the efficiency's u per cell (${JSON.stringify(uMap[0])})`);
  await page.$eval('[data-chart="r-map"]', (e) => e.scrollIntoView());
  await shot(page, artifacts, 'unc-2-map-of-u');
  await page.click('#r-map-u');

  // ---- 4. tables: ± u columns and ME − MTPA significance ----
  const oh = await heads(page, '#r-optima');
  const optima = await rows(page, '#r-optima');
  const col = (h) => oh.indexOf(h);
  const rowOf = (c) => optima.find((r) => r[0] === `${c.estimator} / ${c.pwm}` && Number(r[1]) === c.speed_rpm && Number(r[2]) === c.load_Nm);
  let okT = 0; bad = [];
  for (const c of curves) {
    const r = rowOf(c);
    const want = [fu(c.mtpa_angle_u_deg), fu(c.me_angle_u_deg), fu(c.me.pdcm_u_W), f(c.me_minus_mtpa_deg, 2), fu(c.me_minus_mtpa_u_deg),
      c.me_minus_mtpa_significant === true ? 'yes' : c.me_minus_mtpa_significant === false ? 'no' : '–'];
    const got = r && [r[col('MTPA angle ±u [deg]')], r[col('ME angle ±u [deg]')], r[col('ME P_dcM ±u [W]')], r[col('ME − MTPA [deg]')], r[col('ME − MTPA ±u [deg]')],
      r[col('ME − MTPA significant at 95 %')]];
    if (JSON.stringify(got) === JSON.stringify(want)) okT++; else bad.push(`${JSON.stringify(got)} != ${JSON.stringify(want)}`);
  }
  check(okT === 8 && oh.includes('ME − MTPA significant at 95 %'), `the optima table's ±u and ME − MTPA significance columns equal the analysis (${okT} of 8; ${bad.slice(0, 1)})`);
  const eff = await rows(page, '#r-eff');
  const wantEff = em.loads_Nm.map((l, j) => [f(l, 2), ...em.speeds_rpm.flatMap((s, i) => [f(em.efficiency[i][j] * 100, 1), fu(em.efficiency_u[i][j] * 100)])]);
  check(JSON.stringify(eff) === JSON.stringify(wantEff), `the efficiency table has η and ±u per speed, as the map (${JSON.stringify(eff[0])})`);
  await page.$eval('#r-tables', (e) => e.scrollIntoView());
  await shot(page, artifacts, 'unc-3-tables');

  // ---- 5. comparison: u(diff) from the repeat parts, insignificant marked ----
  await page.goto(`${origin.url}#/results/${s2.id}/vs/${s3.id}`);
  if (await page.$('#signin[open]')) await signIn(page, token);
  check(await until(async () => (await rows(page, '#r-cmp-table')).length >= 4, 15000), `the comparison #${s2.id} vs #${s3.id} opens`);
  const ch = await heads(page, '#r-cmp-table');
  const cmp = await rows(page, '#r-cmp-table');
  const eb = new Map(B.curves.entries.map((e) => [`${e.speed_rpm}|${e.load_Nm}`, e]));
  let okC = 0, knownC = 0; bad = [];
  for (const x of curves.filter((c) => c.estimator === 'encoder' && c.pwm === 'capwm')) {
    const y = eb.get(`${x.speed_rpm}|${x.load_Nm}`);
    const r = cmp.find((q) => q[0] === 'encoder / capwm' && Number(q[1]) === x.speed_rpm && Number(q[2]) === x.load_Nm);
    const ua = known(x.mtpa_angle_u_deg) && known(y.mtpa_angle_u_deg) ? Math.hypot(x.mtpa_angle_u_deg, y.mtpa_angle_u_deg) : null;
    const d = y.mtpa.angle_deg - x.mtpa.angle_deg;
    const sig = ua == null ? '–' : Math.abs(d) > 1.96 * ua ? 'yes' : 'no';
    const got = r && [r[ch.indexOf('u(Δ MTPA angle) [deg]')], r[ch.indexOf('significant at 95 % (MTPA angle, ME angle, η, P_dcM)')].split(', ')[0]];
    if (JSON.stringify(got) === JSON.stringify([fu(ua), sig])) okC++; else bad.push(`${got} != ${fu(ua)},${sig}`);
    if (ua != null) knownC++;
  }
  check(okC === 4 && knownC >= 2, `the comparison table's u(Δ MTPA angle) = sqrt(uA² + uB²) and its significance (|Δ| > 1.96 u) per row (${okC} of 4; ${bad.slice(0, 1)})`);
  const cd = await page.evaluate(() => window.synbench.resultsView.compare.cards.diff.option.series.filter((s) => s.type === 'bar')
    .flatMap((s) => s.data.filter(Boolean)));
  check(cd.length > 0 && cd.every((d) => (d.significant === false) === (d.itemStyle?.opacity < 1)) && cd.some((d) => d.significant != null),
    `the comparison chart fades exactly its insignificant differences (${cd.filter((d) => d.significant === false).length} of ${cd.length})`);
  await page.$eval('#r-compare', (e) => e.scrollIntoView());
  await shot(page, artifacts, 'unc-4-compare');

  // ---- 6. a sweep from before: no uncertainty stored ----
  await page.goto(`${origin.url}#/results/1`);
  check(await until(async () => /no uncertainty stored/i.test(await text(page, '#r-unote')), 15000), `sweep #1 (u NULL): "${await text(page, '#r-unote')}"`);
  const old = await page.evaluate(() => Object.fromEntries(Object.entries(window.synbench.resultsView.cards)
    .map(([k, c]) => [k, { bars: (c.option?.series || []).filter((s) => s.errorBars).length, note: [].concat(c.option?.title || []).map((t) => t?.text).join(' ') }])));
  check(['traj', 'curve', 'eta', 'map'].every((k) => old[k].bars === 0 && old[k].note.includes('no uncertainty stored')),
    `no error bars on the old sweep's charts, each says "no uncertainty stored" (${JSON.stringify(old.traj)})`);
  const oldOptima = await rows(page, '#r-optima');
  const sc = (await heads(page, '#r-optima')).indexOf('ME − MTPA significant at 95 %');
  check(oldOptima.length === 4 && oldOptima.every((r) => r[sc] === '–'), 'the old sweep\'s tables call nothing significant (–)');
  await shot(page, artifacts, 'unc-5-old-sweep');
  check(pageErrors.length === 0, `no uncaught errors on the page (${pageErrors.join('; ')})`);
  await ctx.close();
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  await tearDown({ browser, origin, daemon });
}
finish();
