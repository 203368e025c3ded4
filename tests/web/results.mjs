// The Results view in headless Chromium (docs/dashboard.md, "3 Results"): two sweeps stored by
// the CLI (different angle grids, a load only in each) compared on #/results/1/vs/2 (the overlay
// labelled per run, the difference table equal to differences of the two analyses from REST,
// points only in one run listed, the choice kept in the URL over a reload), the numeric tables
// equal to the analysis at their printed precision and copied as CSV, a titled PNG export with
// its file name, and the charts' points read with the keyboard only. The two sweeps come from two
// benches sharing one store (`--bench-name`): the History view names each run's bench, filters by
// bench, and opens two ticked runs of different benches in the comparison.
//
// usage: node results.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import {
  args, loadPlaywright, launch, check, finish, until, shot, tmpDir, startDaemon, pageOrigin,
  signIn, text, log, rest, tearDown,
} from './harness.mjs';

const { bin, webDir, artifacts } = args();
const pw = loadPlaywright(webDir);

const dataDir = path.join(tmpDir('synbench-web-results-'), 'data');
fs.mkdirSync(dataDir, { recursive: true });
const configurations = [{ estimator: 'encoder', pwm: 'capwm' }, { estimator: 'ekf-basic', pwm: 'aspwm' }];
const sweep = (name, loads, angle, bench) => {
  const file = path.join(dataDir, '..', `${name}.json`);
  fs.writeFileSync(file, JSON.stringify({ name, window_s: 0.5, dimensions: { speed_rpm: [500, 900], load_Nm: loads, angle_deg: angle, configurations } }));
  execFileSync(bin, ['sweep', file, '--db', path.join(dataDir, 'synbench.db'), '--bench-name', bench], { stdio: 'ignore' });
};
sweep('run A fine grid', [1, 2, 3], { from: 42, to: 66, step: 4 }, 'bench-a');   // sweep #1
sweep('run B coarse grid', [0.5, 1, 2], { from: 44, to: 68, step: 6 }, 'bench-b'); // sweep #2
const daemon = await startDaemon(bin, dataDir, { webDir });
const origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const browser = await launch(pw);
const pageErrors = [];

const get = async (p) => (await rest(daemon.url, 'GET', p, token)).json;
const f = (v, d) => (v == null || !Number.isFinite(v) ? '–' : v.toFixed(d));
const ckey = (c) => `${c.estimator}/${c.pwm}`;
const pkey = (c) => `${ckey(c)}|${c.speed_rpm}|${c.load_Nm}`;
const rows = (page, sel) => page.$$eval(`${sel} tbody tr`, (trs) => trs.map((tr) => [...tr.children].map((c) => c.textContent.trim())));
// the columns of a table named in want (its other columns, the uncertainties, are uncertainty.mjs's)
const columns = async (page, sel, want) => {
  const head = await page.$$eval(`${sel} thead th`, (ths) => ths.map((c) => c.textContent.trim()));
  const k = want.map((h) => head.indexOf(h));
  return (await rows(page, sel)).map((r) => k.map((i) => r[i]));
};

try {
  const A = await get('/api/sweeps/1/analysis');
  const B = await get('/api/sweeps/2/analysis');
  const sweeps = await get('/api/sweeps');
  check(A?.curves?.entries?.length === 12 && B?.curves?.entries?.length === 12, 'two stored sweeps with 12 curves each');
  const dateA = (sweeps.find((s) => s.id === 1).finished_at || sweeps.find((s) => s.id === 1).created_at).slice(0, 10);

  const ctx = await browser.newContext({ viewport: { width: 1280, height: 900 }, acceptDownloads: true });
  await ctx.grantPermissions(['clipboard-read', 'clipboard-write'], { origin: new URL(origin.url).origin });
  const page = await ctx.newPage();
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(origin.url);
  await signIn(page, token);

  // ---- 0. runs of two benches in one store: History names, filters, compares ----
  check(sweeps.find((s) => s.id === 1)?.bench?.name === 'bench-a' && sweeps.find((s) => s.id === 2)?.bench?.name === 'bench-b'
    && sweeps.every((s) => s.bench.host && Array.isArray(s.bench.devices)), `REST names each sweep's bench (${JSON.stringify(sweeps.map((s) => s.bench))})`);
  await page.goto(`${origin.url}#/history`);
  const hist = () => page.$$eval('#history tbody tr', (trs) => trs.map((tr) => ({ id: Number(tr.dataset.id), bench: tr.querySelector('.bench')?.textContent.trim() })));
  check(await until(async () => (await hist()).length === 2, 10000), 'History lists both runs');
  const h2 = await hist();
  check(h2.every((r) => r.bench.startsWith(r.id === 1 ? 'bench-a' : 'bench-b')), `each row names its bench (${JSON.stringify(h2)})`);
  const benchOpts = await page.$$eval('#history-bench option', (os) => os.map((o) => o.value));
  check(JSON.stringify(benchOpts) === JSON.stringify(['', 'bench-a', 'bench-b']), `the bench filter offers all, bench-a, bench-b (${benchOpts})`);
  await page.selectOption('#history-bench', 'bench-b');
  const hb = await hist();
  check(hb.length === 1 && hb[0].id === 2, `filtered to bench-b: only sweep #2 (${JSON.stringify(hb)})`);
  await page.selectOption('#history-bench', '');
  check(await until(async () => (await hist()).length === 2, 5000), 'all benches again: both runs');
  check(await page.$eval('#history-compare', (b) => b.disabled), 'Compare selected is disabled with nothing ticked');
  await page.check('#history input[data-tick="2"]');
  await page.check('#history input[data-tick="1"]');
  const note = await text(page, '#history-compare-note');
  check(!(await page.$eval('#history-compare', (b) => b.disabled)) && /#2 on bench-b.* against #1 on bench-a/.test(note), `two ticked runs of two benches: "${note}"`);
  await page.click('#history-compare');
  check(await until(async () => page.url().endsWith('#/results/1/vs/2') && (await rows(page, '#r-cmp-table')).length > 1, 15000),
    'Compare selected opens #/results/1/vs/2 with the difference table');
  const vsLabel = await page.$eval('#r-vs', (e) => e.selectedOptions[0]?.textContent || '');
  check(/#2 run B coarse grid on bench-b/.test(vsLabel), `the comparison's run is named with its bench ("${vsLabel}")`);

  // ---- 1. compare two runs, from a link ----
  await page.goto(`${origin.url}#/results/1/vs/2`);
  if (await page.$('#signin[open]')) await signIn(page, token);
  const cfg = { estimator: 'ekf-basic', pwm: 'aspwm' }; // the view's default: the estimator
  check(await until(async () => (await rows(page, '#r-cmp-table')).length > 1, 15000), 'the link #/results/1/vs/2 opens the comparison');
  check(await page.$eval('#r-vs', (e) => e.value) === '2', 'the "Compare with" choice is sweep #2');
  const ea = new Map(A.curves.entries.map((e) => [pkey(e), e]));
  const eb = new Map(B.curves.entries.map((e) => [pkey(e), e]));
  const keys = new Set([...ea.keys(), ...eb.keys()]);
  const table = await rows(page, '#r-cmp-table');
  check(table.length === keys.size, `one difference row per configuration x speed x load of either run (${table.length} of ${keys.size})`);
  let same = 0, onlyA = 0, onlyB = 0, bad = [];
  for (const r of table) {
    const k = `${r[0].replace(' / ', '/')}|${Number(r[1])}|${Number(r[2])}`;
    const x = ea.get(k), y = eb.get(k);
    if (x && y) {
      const want = ['both', f(y.mtpa.angle_deg - x.mtpa.angle_deg, 2), f(y.me.angle_deg - x.me.angle_deg, 2),
        f((y.me.efficiency - x.me.efficiency) * 100, 2), f(y.me.pdcm_W - x.me.pdcm_W, 2)];
      if (JSON.stringify(r.slice(3, 8)) === JSON.stringify(want)) same++; else bad.push(`${k}: ${r.slice(3)} != ${want}`);
    } else if (x && r[3] === 'only in #1' && r.slice(4).every((c) => c === '–')) onlyA++;
    else if (y && r[3] === 'only in #2' && r.slice(4).every((c) => c === '–')) onlyB++;
    else bad.push(`${k}: ${r}`);
  }
  check(same === 8 && bad.length === 0, `the differences #2 − #1 equal those of the two analyses from REST (${same} rows; ${bad.slice(0, 3).join('; ')})`);
  check(onlyA === 4 && onlyB === 4, `points in one run only are listed as such (${onlyA} only in #1, ${onlyB} only in #2)`);
  const sameCount = [...ea.keys()].filter((k) => eb.has(k) && k.startsWith(ckey(cfg))).length;
  const opts = await page.evaluate(() => {
    const c = window.synbench.resultsView.compare.cards;
    return { traj: c.traj.option.series.map((s) => s.name), curve: c.curve.option.series.map((s) => s.name),
      diff: c.diff.option.series.map((s) => ({ name: s.name, data: s.data })) };
  });
  check(opts.traj.some((n) => n.startsWith('sweep #1 ekf-basic / aspwm')) && opts.traj.some((n) => n.startsWith('sweep #2 ekf-basic / aspwm')) && opts.traj.length === 8,
    `the trajectory overlay has both runs' MTPA and ME series, labelled by sweep (${opts.traj.slice(0, 2).join(', ')} ...)`);
  check(opts.curve.filter((n) => n.startsWith('sweep #1')).length === 2 && opts.curve.filter((n) => n.startsWith('sweep #2')).length === 2,
    `the I_m/P_dcM overlay has both runs' curves (${opts.curve.join(', ')})`);
  const dMtpa = opts.diff.find((s) => s.name === 'Δ MTPA angle').data.map((d) => d?.value ?? d);
  const wantMtpa = [...ea.values()].filter((x) => ckey(x) === ckey(cfg) && eb.has(pkey(x)))
    .sort((p, q) => p.speed_rpm - q.speed_rpm || p.load_Nm - q.load_Nm)
    .map((x) => Number((eb.get(pkey(x)).mtpa.angle_deg - x.mtpa.angle_deg).toFixed(4)));
  check(dMtpa.length === sameCount && JSON.stringify(dMtpa) === JSON.stringify(wantMtpa), `the difference chart's ΔMTPA bars are the REST differences (${dMtpa})`);
  await page.waitForTimeout(300);
  await page.screenshot({ path: path.join(artifacts, 'results-1-compare.png'), fullPage: true });
  log('screenshot', path.join(artifacts, 'results-1-compare.png'));

  await page.reload();
  if (await page.$('#signin[open]')) await signIn(page, token);
  check(await until(async () => (await rows(page, '#r-cmp-table')).length === keys.size, 15000)
    && await page.$eval('#r-vs', (e) => e.value) === '2' && page.url().endsWith('#/results/1/vs/2'), 'a reload shows the same comparison');
  await page.selectOption('#r-vs', '');
  check(await until(async () => page.url().endsWith('#/results/1') && await page.$eval('#r-compare', (e) => e.hidden), 5000), 'no comparison: the URL is #/results/1 and the panel is hidden');
  await page.selectOption('#r-vs', '2');
  check(await until(async () => page.url().endsWith('#/results/1/vs/2') && !(await page.$eval('#r-compare', (e) => e.hidden)), 10000), 'choosing sweep #2 again puts /vs/2 in the URL');

  // ---- 2. numeric tables ----
  const optima = await columns(page, '#r-optima', ['configuration', 'speed [rpm]', 'load [N m]',
    ...['MTPA', 'ME'].flatMap((t) => [`${t} angle [deg]`, `${t} I_m [A]`, `${t} P_dcM [W]`, `${t} η [%]`, `${t} note`])]);
  const order = ['encoder/capwm', 'ekf-basic/aspwm'];
  const want = A.curves.entries.slice().sort((p, q) => order.indexOf(ckey(p)) - order.indexOf(ckey(q)) || p.speed_rpm - q.speed_rpm || p.load_Nm - q.load_Nm)
    .map((e) => {
      const o = (x) => [f(x.angle_deg, 2), f(x.im_A, 3), f(x.pdcm_W, 1), f(x.efficiency * 100, 1), [x.at_edge ? 'at edge' : '', x.refined ? 'refined' : ''].filter(Boolean).join(', ')];
      return [`${e.estimator} / ${e.pwm}`, f(e.speed_rpm, 0), f(e.load_Nm, 2), ...o(e.mtpa), ...o(e.me)];
    });
  check(JSON.stringify(optima) === JSON.stringify(want), `the optima table equals the analysis at its printed precision (${optima.length} rows; first ${optima[0]})`);
  check(want.some((r) => r[7] === 'at edge' || r[12] === 'at edge') ? optima.some((r) => r[7] === 'at edge' || r[12] === 'at edge') : optima.some((r) => r[7] === 'refined'),
    'the optima table marks "at edge" / "refined" as the analysis does');
  const em = A.efficiency_map.entries.find((e) => ckey(e) === ckey(cfg));
  const eff = await columns(page, '#r-eff', ['load [N m]', ...em.speeds_rpm.map((s) => `η [%] at ${s} rpm`)]);
  const wantEff = em.loads_Nm.map((l, j) => [f(l, 2), ...em.speeds_rpm.map((s, i) => f(em.efficiency[i][j] * 100, 1))]);
  check(JSON.stringify(eff) === JSON.stringify(wantEff), `the efficiency table (rows load, columns speed) equals the map (${JSON.stringify(eff[0])})`);
  await page.click('#r-optima-copy');
  const csv = await until(async () => { const t = await page.evaluate(() => navigator.clipboard.readText()); return t.startsWith('configuration,') ? t : null; }, 5000);
  const lines = (csv || '').trim().split('\n');
  const first = want[0];
  const row1 = (lines[1] || '').split(',');
  check(lines.length === 13 && Number(row1[3]).toFixed(2) === first[3] && row1[0] === first[0],
    `Copy CSV: header and 12 rows in the clipboard, unrounded (${lines[1]})`);
  await page.click('#r-eff-copy');
  const csv2 = await until(async () => { const t = await page.evaluate(() => navigator.clipboard.readText()); return t.startsWith('load [N m],') ? t : null; }, 5000);
  check(csv2 && csv2.trim().split('\n').length === 4, 'Copy CSV of the efficiency table: header and one row per load');
  await page.$eval('#r-tables', (e) => e.scrollIntoView());
  await shot(page, artifacts, 'results-2-tables');

  // ---- 3. titled exports ----
  const [dl] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), page.click('[data-chart="r-traj"] header button')]);
  const wantName = `synbench-1-mtpa-me-angle-ekf-basic-aspwm-${dateA}.png`;
  check(dl.suggestedFilename() === wantName, `the PNG's file name is ${dl.suggestedFilename()} (want ${wantName})`);
  const ex = await page.evaluate(() => window.synbench.lastExport);
  const t0 = ex?.titles?.[0] || '';
  check(t0.includes('MTPA') && t0.includes('sweep #1') && t0.includes('run A fine grid') && t0.includes('ekf-basic / aspwm') && t0.includes(dateA),
    `the exported chart carries the title: ${JSON.stringify(t0)}`);
  const png = fs.readFileSync(await dl.path());
  check(png.subarray(1, 4).toString() === 'PNG' && png.readUInt32BE(20) === ex.height * 2, `the PNG is the titled chart (${png.readUInt32BE(16)} x ${png.readUInt32BE(20)} px)`);
  fs.copyFileSync(await dl.path(), path.join(artifacts, 'results-export-titled.png'));
  const [dl2] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), page.click('[data-chart="r-cmp-diff"] header button')]);
  const t2 = (await page.evaluate(() => window.synbench.lastExport))?.titles?.[0] || '';
  check(dl2.suggestedFilename() === `synbench-1-difference-vs-2-ekf-basic-aspwm-${dateA}.png` && t2.includes('sweep #2') && t2.includes('run B coarse grid'),
    `the comparison's export names both runs (${dl2.suggestedFilename()}; ${JSON.stringify(t2)})`);
  fs.copyFileSync(await dl2.path(), path.join(artifacts, 'results-export-difference.png'));

  // ---- 4. the keyboard only ----
  await page.evaluate(() => { document.activeElement?.blur(); window.scrollTo(0, 0); });
  await page.focus('#r-load');
  let reached = false;
  for (let i = 0; i < 40 && !reached; i++) {
    await page.keyboard.press('Tab');
    reached = await page.evaluate(() => document.activeElement?.closest('[data-chart="r-map"]') && document.activeElement.classList.contains('chart'));
  }
  check(reached, 'Tab reaches the efficiency map chart');
  await page.keyboard.press('ArrowRight');
  const s500 = em.speeds_rpm.indexOf(500);
  const wantMap = `speed [rpm] ${em.speeds_rpm[0]}, load torque T_L [N m] ${em.loads_Nm[0]}: ${Number((em.efficiency[0][0] * 100).toFixed(1))}`;
  const mapRead = await text(page, '[data-chart="r-map"] .point-readout');
  check(s500 === 0 && mapRead.includes(wantMap), `the map's first cell is read out: ${mapRead}`);
  for (let i = 0; i < 10 && !(await page.evaluate(() => document.activeElement?.closest('[data-chart="r-traj"]') && document.activeElement.classList.contains('chart'))); i++)
    await page.keyboard.press('Tab');
  const cur = A.curves.entries.filter((e) => ckey(e) === ckey(cfg) && e.speed_rpm === 500).sort((p, q) => p.load_Nm - q.load_Nm);
  await page.keyboard.press('ArrowRight');
  await page.keyboard.press('ArrowRight');
  const r1 = await text(page, '[data-chart="r-traj"] .point-readout');
  check(r1 === `MTPA 500 rpm: load torque T_L [N m] ${cur[1].load_Nm}, current angle θ_i [deg] ${Number(cur[1].mtpa.angle_deg.toFixed(2))} (point 2 of 3)`,
    `Right, Right: the second MTPA point is read out (${r1})`);
  await page.keyboard.press('ArrowDown');
  const r2 = await text(page, '[data-chart="r-traj"] .point-readout');
  check(r2 === `ME 500 rpm: load torque T_L [N m] ${cur[1].load_Nm}, current angle θ_i [deg] ${Number(cur[1].me.angle_deg.toFixed(2))} (point 2 of 3)`,
    `Down: the ME point at the same load (${r2})`);
  check(await until(async () => page.$eval('[data-chart="r-traj"] .chart', (e) => [...e.querySelectorAll('div')].some((d) => d.style.display !== 'none' && /ME 500 rpm/.test(d.textContent))), 3000),
    'the tooltip shows the point chosen by keyboard');
  await page.$eval('[data-chart="r-traj"]', (e) => e.scrollIntoView());
  await shot(page, artifacts, 'results-3-keyboard');
  check(pageErrors.length === 0, `no uncaught errors on the page (${pageErrors.join('; ')})`);
  await ctx.close();
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  await tearDown({ browser, origin, daemon });
}
finish();
