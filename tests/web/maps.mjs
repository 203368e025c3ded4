// Every efficiency map the same way round (issue 44, item 3; docs/dashboard.md "3 Results"):
// two sweeps stored by the CLI (#1: 3 speeds x 3 loads, #2: 2 x 2). The Results view's efficiency
// map has speed on x and torque on y, as its contour card and the HTML report (GET
// /api/sweeps/1/report) have; the map and the contour card use one colour scale and one range,
// the report's (its viridis ramp between its scale's end labels); the contour card marks the
// measured points, and says so when a field rests on few points (#2), not otherwise (#1).
// Screenshots: ARTIFACT_DIR/maps-{1440,1024,390}.png, maps-few-points.png.
//
// usage: node maps.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import {
  args, loadPlaywright, launch, check, finish, until, shot, tmpDir, startDaemon, pageOrigin,
  signIn, text, attr, log, rest, tearDown,
} from './harness.mjs';

const { bin, webDir, artifacts } = args();
const pw = loadPlaywright(webDir);

const dataDir = path.join(tmpDir('synbench-web-maps-'), 'data');
fs.mkdirSync(dataDir, { recursive: true });
const store = (name, speeds, loads) => {
  const file = path.join(dataDir, '..', `${name}.json`);
  fs.writeFileSync(file, JSON.stringify({ name, window_s: 0.2,
    dimensions: { speed_rpm: speeds, load_Nm: loads, angle_deg: { from: 44, to: 64, step: 5 },
      configurations: [{ estimator: 'encoder', pwm: 'capwm' }] } }));
  execFileSync(bin, ['sweep', file, '--db', path.join(dataDir, 'synbench.db'), '--quiet'], { stdio: 'ignore' });
};
store('map three by three', [300, 600, 900], [0.5, 1.5, 2.5]);
store('map two by two', [400, 800], [1, 2]);

const daemon = await startDaemon(bin, dataDir, { webDir });
const origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const browser = await launch(pw);
const pageErrors = [];
const VIRIDIS = ['#440154', '#3b528b', '#21918c', '#5ec962', '#fde725'];
const f1 = (v) => Number(v).toFixed(1);

// What the report's two heat maps of a configuration say: axis labels, x categories, the colour
// scale's end labels and the fills of its lowest and highest cells.
async function reportMaps(page, html) {
  await page.setContent(html);
  return page.$$eval('svg.plot', (svgs) => svgs.map((s) => {
    const title = s.querySelector('title')?.textContent || '';
    if (!/^Efficiency (map|contours)/.test(title)) return null;
    const labels = [...s.querySelectorAll('g.ax text.l')].map((t) => t.textContent);
    const xcats = [...s.querySelectorAll('g.ax text[text-anchor="middle"]:not(.l)')].map((t) => t.textContent);
    const scale = [...s.querySelectorAll('g.scale text')].map((t) => t.textContent);
    const cells = [...s.querySelectorAll('g.cells rect')].map((r) => r.getAttribute('fill'));
    const values = [...s.querySelectorAll('g.cells text')].map((t) => Number(t.textContent));
    return { title, labels, xcats, scale, cells, values, kind: title.startsWith('Efficiency map') ? 'map' : 'contours' };
  }).filter(Boolean));
}

try {
  const ctx = await browser.newContext({ viewport: { width: 1440, height: 1000 } });
  const page = await ctx.newPage();
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(`${origin.url}#/results/1`);
  await signIn(page, token);
  check(!!(await until(async () => (await text(page, '#r-summary')).startsWith('Sweep #1'), 15000)), 'the Results view shows sweep #1');
  const A = (await rest(daemon.url, 'GET', '/api/sweeps/1/analysis', token)).json;
  const em = A.efficiency_map.entries[0];
  check(em.speeds_rpm.length === 3 && em.loads_Nm.length === 3, `sweep #1's map is 3 speeds x 3 loads (${em.speeds_rpm} rpm; ${em.loads_Nm} N m)`);
  await until(async () => Number(await attr(page, '[data-chart="r-map"]', 'data-points')) === 9 && Number(await attr(page, '[data-chart="r-contour"]', 'data-points')) > 9, 10000);
  const opt = (card) => page.evaluate((c) => {
    const o = window.synbench.resultsView.cards[c].option;
    const ax = (a) => ({ name: a.name, data: a.data ?? null, type: a.type });
    const vm = [].concat(o.visualMap)[0];
    return { x: ax([].concat(o.xAxis)[0]), y: ax([].concat(o.yAxis)[0]), vm: { min: vm.min, max: vm.max, colours: vm.inRange.color },
      series: o.series.map((s) => ({ name: s.name, type: s.type, data: (s.data || []).map((d) => (Array.isArray(d) ? d : d.value)) })),
      title: [].concat(o.title || []).map((t) => t?.text || '') };
  }, card);
  const map = await opt('map');
  const con = await opt('contour');

  // ---- 1. one orientation: speed on x, torque on y ----
  check(map.x.name === 'speed [rpm]' && JSON.stringify(map.x.data) === JSON.stringify(em.speeds_rpm.map(String)),
    `the efficiency map has speed on x (${map.x.name}: ${map.x.data})`);
  check(map.y.name === 'load torque T_L [N m]' && JSON.stringify(map.y.data) === JSON.stringify(em.loads_Nm.map(String)),
    `the efficiency map has torque on y (${map.y.name}: ${map.y.data})`);
  check(con.x.name === map.x.name && con.y.name === map.y.name, `the contour card has the same axes (${con.x.name}; ${con.y.name})`);
  // A cell is where its speed and load are: [speed index, load index, η %].
  const cell = map.series[0].data.find((d) => d[0] === 2 && d[1] === 0);
  check(cell && Math.abs(cell[2] - em.efficiency[2][0] * 100) < 0.051,
    `the cell at x = ${em.speeds_rpm[2]} rpm, y = ${em.loads_Nm[0]} N m holds that point's η (${cell?.[2]} %, analysis ${f1(em.efficiency[2][0] * 100)} %)`);

  const report = await rest(daemon.url, 'GET', '/api/sweeps/1/report', token);
  check(report.status === 200 && report.text.includes('<svg'), `the HTML report of sweep #1 (${report.text.length} bytes)`);
  const rp = await ctx.newPage();
  const rmaps = await reportMaps(rp, report.text);
  const rmap = rmaps.find((m) => m.kind === 'map');
  const rcon = rmaps.find((m) => m.kind === 'contours');
  check(!!rmap && !!rcon, `the report has the measured map and the contours (${rmaps.map((m) => m.kind)})`);
  check(rmap && rmap.labels[0] === map.x.name && rmap.labels[1] === map.y.name && rcon.labels[0] === con.x.name && rcon.labels[1] === con.y.name,
    `the dashboard's axes are the report's (report: x "${rmap?.labels[0]}", y "${rmap?.labels[1]}")`);
  check(rmap && JSON.stringify(rmap.xcats.slice(0, 3)) === JSON.stringify(em.speeds_rpm.map(String)),
    `the report's map has the speeds along x as the dashboard's (${rmap?.xcats.slice(0, 3)})`);

  // ---- 2. one colour scale and range ----
  check(JSON.stringify(map.vm.colours) === JSON.stringify(VIRIDIS) && JSON.stringify(con.vm.colours) === JSON.stringify(VIRIDIS),
    `the map and the contours use the report's colour ramp (${map.vm.colours.join(' ')})`);
  check(map.vm.min === con.vm.min && map.vm.max === con.vm.max, `the map and the contours share one range (${f1(map.vm.min)} .. ${f1(map.vm.max)} %; contours ${f1(con.vm.min)} .. ${f1(con.vm.max)} %)`);
  const etas = em.efficiency.flat().filter((v) => v != null).map((v) => v * 100);
  check(Math.abs(map.vm.min - Math.min(...etas)) < 1e-9 && Math.abs(map.vm.max - Math.max(...etas)) < 1e-9,
    'the range runs from the lowest to the highest measured cell');
  for (const r of [rmap, rcon]) {
    const [hi, lo] = (r?.scale || []).map((t) => t.replace(' %', ''));
    check(hi === f1(map.vm.max) && lo === f1(map.vm.min), `the report's ${r?.kind} scale reads ${lo} .. ${hi} %, the dashboard's ${f1(map.vm.min)} .. ${f1(map.vm.max)} %`);
  }
  const imax = rmap ? rmap.values.indexOf(Math.max(...rmap.values)) : -1;
  const imin = rmap ? rmap.values.indexOf(Math.min(...rmap.values)) : -1;
  check(rmap && rmap.cells[imax] === VIRIDIS[4] && rmap.cells[imin] === VIRIDIS[0],
    `the report's highest cell is the ramp's top colour and its lowest the bottom (${rmap?.cells[imax]}, ${rmap?.cells[imin]})`);
  await rp.close();

  // ---- 3. measured points on the contour map; no few-points note on a 3 x 3 field ----
  const measured = con.series.find((s) => s.name === 'measured points');
  const want = em.speeds_rpm.flatMap((s, i) => em.loads_Nm.map((l, j) => (em.efficiency[i][j] == null ? null : `${s}|${l}`))).filter(Boolean).sort();
  check(!!measured && JSON.stringify(measured.data.map((d) => `${d[0]}|${d[1]}`).sort()) === JSON.stringify(want),
    `the contour map marks the ${want.length} measured points at their speed and load (${measured?.data.length})`);
  check(Number(await attr(page, '[data-chart="r-contour"]', 'data-measured-points')) === want.length
    && (await attr(page, '[data-chart="r-contour"]', 'data-few-points')) === 'false' && !con.title.join(' ').includes('interpolated from only'),
    `a 3 x 3 field carries no few-points note ("${con.title.join(' ')}")`);
  await page.$eval('[data-chart="r-map"]', (e) => e.scrollIntoView({ block: 'center' }));
  await shot(page, artifacts, 'maps-1440');

  // ---- 4. a 2 x 2 field: the note ----
  await page.selectOption('#r-sweep', '2');
  check(!!(await until(async () => (await attr(page, '[data-chart="r-contour"]', 'data-few-points')) === 'true', 10000)), 'sweep #2\'s field is marked as resting on few points');
  const note = await attr(page, '[data-chart="r-contour"]', 'data-note');
  const con2 = await opt('contour');
  check(note.includes('only 4 measured points') && con2.title.join(' ').replace(/\n/g, ' ').includes(note), `the contour card says so: "${note}"`);
  check(con2.series.find((s) => s.name === 'measured points')?.data.length === 4, 'its 4 measured points are marked');
  await page.$eval('[data-chart="r-contour"]', (e) => e.scrollIntoView({ block: 'center' }));
  await shot(page, artifacts, 'maps-few-points');

  // ---- the Results maps at tablet and phone width ----
  await page.selectOption('#r-sweep', '1');
  await until(async () => (await text(page, '#r-summary')).startsWith('Sweep #1'), 10000);
  for (const [w, h] of [[1024, 900], [390, 844]]) {
    await page.setViewportSize({ width: w, height: h });
    await page.waitForTimeout(400);
    await page.$eval('[data-chart="r-map"]', (e) => e.scrollIntoView({ block: 'center' }));
    const wide = await page.evaluate(() => document.documentElement.scrollWidth);
    check(wide <= w, `at ${w} px the Results view is no wider than the screen (${wide} px)`);
    await shot(page, artifacts, `maps-${w}`);
  }
  check(pageErrors.length === 0, `no page errors (${pageErrors.join('; ')})`);
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  await tearDown({ browser, origin, daemon });
  log('done');
}
finish();
