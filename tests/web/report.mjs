// The Results view's contour map and one-click report in headless Chromium (docs/dashboard.md,
// docs/report.md): a two-configuration sweep stored by the CLI; the contour chart draws the
// interpolated field with labelled iso-lines; the Report button downloads the self-contained HTML
// (> 20 KB, inline SVG, no script) and the points CSV; the report opens from file:// and shows
// its figures. Screenshots: ARTIFACT_DIR/report-*.png.
//
// usage: node report.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import {
  args, loadPlaywright, launch, check, finish, until, tmpDir, startDaemon, pageOrigin,
  signIn, text, attr, log, rest, tearDown,
} from './harness.mjs';

const { bin, webDir, artifacts } = args();
const pw = loadPlaywright(webDir);
fs.mkdirSync(artifacts, { recursive: true });

const dataDir = path.join(tmpDir('synbench-web-report-'), 'data');
fs.mkdirSync(dataDir, { recursive: true });
const planFile = path.join(dataDir, '..', 'plan.json');
fs.writeFileSync(planFile, JSON.stringify({ name: 'contours and report', window_s: 0.5,
  dimensions: { speed_rpm: [300, 600, 900], load_Nm: [1, 2, 3], angle_deg: { from: 42, to: 66, step: 4 },
    configurations: [{ estimator: 'encoder', pwm: 'capwm' }, { estimator: 'ekf-basic', pwm: 'aspwm' }] } }));
execFileSync(bin, ['sweep', planFile, '--db', path.join(dataDir, 'synbench.db')], { stdio: 'ignore' });
const daemon = await startDaemon(bin, dataDir, { webDir });
const origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const browser = await launch(pw);
const pageErrors = [];

try {
  const ctx = await browser.newContext({ viewport: { width: 1280, height: 900 }, acceptDownloads: true });
  const page = await ctx.newPage();
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(origin.url);
  await signIn(page, token);
  await page.keyboard.press('3');
  await page.waitForSelector('#view-results:not([hidden])');
  await until(async () => (await text(page, '#r-summary')).startsWith('Sweep #1'), 10000);

  // ---- the contour map ----
  const analysis = (await rest(daemon.url, 'GET', '/api/sweeps/1/analysis', token)).json;
  const entry = analysis.efficiency_contours.entries.find((e) => e.estimator === 'encoder');
  const wantSegs = entry.lines.reduce((n, l) => n + l.segments.length, 0);
  check(wantSegs > 0, `the analysis has iso-lines for encoder/capwm (${entry.lines.length} levels, ${wantSegs} segments)`);
  await page.selectOption('#r-config', 'encoder/capwm');
  const card = '[data-chart="r-contour"]';
  check(await until(async () => Number(await attr(page, card, 'data-points')) > 0, 10000), 'the contour chart draws the field');
  check(Number(await attr(page, card, 'data-iso-segments')) === wantSegs, `every iso-line segment is drawn (${await attr(page, card, 'data-iso-segments')} of ${wantSegs})`);
  check(Number(await attr(page, card, 'data-iso-levels')) === entry.lines.length, 'one label per iso-line level');
  check((await text(page, `${card} h3`)).includes('encoder / capwm'), 'the contour card says its configuration');
  // The canvas is not blank where a line runs: dark iso-line pixels among the heat colours.
  const dark = await page.$eval(`${card} canvas`, (c) => {
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) if (d[i] < 40 && d[i + 1] < 40 && d[i + 2] < 40 && d[i + 3] > 200) n++;
    return n;
  });
  check(dark > 200, `iso-lines are on the canvas (${dark} dark pixels)`);
  await page.$eval(card, (e) => e.scrollIntoView());
  const box = await page.$(card);
  await box.screenshot({ path: path.join(artifacts, 'report-contour-chart.png') });
  log('screenshot', path.join(artifacts, 'report-contour-chart.png'));

  // ---- the Report button: the HTML and the CSV ----
  const downloads = [];
  page.on('download', (d) => downloads.push(d));
  await page.click('#r-report');
  check(await until(async () => downloads.length >= 2, 30000), `the Report button downloads two files (${downloads.length})`);
  const html = downloads.find((d) => d.suggestedFilename().endsWith('.html'));
  const csv = downloads.find((d) => d.suggestedFilename().endsWith('.csv'));
  check(html && /^synbench-report-1-contours-and-report-\d{4}-\d{2}-\d{2}\.html$/.test(html.suggestedFilename()), `report name: ${html?.suggestedFilename()}`);
  const htmlPath = path.join(artifacts, 'report-download.html');
  await html.saveAs(htmlPath);
  const body = fs.readFileSync(htmlPath, 'utf8');
  check(body.length > 20000, `the report is > 20 KB (${body.length} bytes)`);
  check(body.includes('<svg') && !/<script|<link|\bsrc=|\bhref=/i.test(body), 'inline SVG, no script or external resource');
  const csvText = fs.readFileSync(await csv.path(), 'utf8');
  check(csv.suggestedFilename() === html.suggestedFilename().replace(/\.html$/, '.csv'), `CSV named like the report: ${csv.suggestedFilename()}`);
  check(csvText.split('\n').filter(Boolean).length === 1 + 2 * 3 * 3 * 7, 'the CSV has every point');

  // ---- the report opened from file:// ----
  const rp = await ctx.newPage();
  await rp.goto('file://' + htmlPath);
  const figs = await rp.$$eval('figure svg', (s) => s.length);
  check(figs >= 10, `the report shows its figures (${figs})`);
  check((await rp.$$eval('svg g.iso', (g) => g.length)) > 0, 'the report draws iso-lines');
  check((await rp.$$eval('#optima tbody tr', (r) => r.length)) === analysis.curves.entries.length, 'the optima table has every curve');
  await rp.setViewportSize({ width: 1100, height: 1400 });
  await rp.screenshot({ path: path.join(artifacts, 'report-file-top.png') });
  await rp.$eval('figure:nth-of-type(2)', (e) => e.scrollIntoView());
  await rp.locator('figure svg').nth(1).screenshot({ path: path.join(artifacts, 'report-file-contours.png') });
  log('screenshots', path.join(artifacts, 'report-file-top.png'), path.join(artifacts, 'report-file-contours.png'));
  check(pageErrors.length === 0, `no uncaught errors on the page (${pageErrors.join('; ')})`);
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  await tearDown({ browser, origin, daemon });
}
finish();
