// A reload never asks for a sign-in it does not need (issue 42, item 2): signed in with
// "Remember on this device", F5 on every view (#/live, #/sweep, #/results/1, #/history) and a
// results link opened in a new tab of the same browser sign in with the saved token, show no
// sign-in dialog, and send no request the daemon refuses with a 401 (the views ask for their data
// only once the token is set). A page with no saved token sends nothing but /api/health before
// its sign-in, and shows the dialog.
//
// usage: node reload.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import {
  args, loadPlaywright, launch, check, finish, until, tmpDir, startDaemon, pageOrigin, text, log, tearDown,
} from './harness.mjs';

const { bin, webDir } = args();
const pw = loadPlaywright(webDir);

const dataDir = path.join(tmpDir('synbench-web-reload-'), 'data');
fs.mkdirSync(dataDir, { recursive: true });
const planFile = path.join(dataDir, '..', 'plan.json');
fs.writeFileSync(planFile, JSON.stringify({ name: 'reload', window_s: 0.2,
  dimensions: { speed_rpm: [300, 600], load_Nm: [1, 2], angle_deg: [50, 60], configurations: [{ estimator: 'encoder', pwm: 'capwm' }] } }));
execFileSync(bin, ['sweep', planFile, '--db', path.join(dataDir, 'synbench.db'), '--quiet'], { stdio: 'ignore' });

const daemon = await startDaemon(bin, dataDir, { webDir });
const origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const browser = await launch(pw);
const pageErrors = [];

// Every API answer of a page, kept: a 401 is what opened the dialog.
function watch(page) {
  const seen = [];
  page.on('response', (r) => { if (r.url().includes('/api/')) seen.push({ status: r.status(), path: new URL(r.url()).pathname }); });
  page.on('pageerror', (e) => pageErrors.push(e.message));
  return seen;
}
const dialogOpen = (page) => page.$eval('#signin', (d) => d.open).catch(() => null);

// What each view shows once its data is in.
const READY = {
  live: async (page) => (await text(page, '#role-pill')) === 'operator',
  sweep: async (page) => /points/.test(await text(page, '#b-estimate')),
  results: async (page) => (await text(page, '#r-summary')).startsWith('Sweep #1'),
  history: async (page) => (await page.$$('#history tbody tr[data-id], #history tbody tr td a')).length > 0,
};

try {
  const ctx = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await ctx.newPage();
  const first = watch(page);
  await page.goto(`${origin.url}#/results/1`);
  await page.waitForSelector('#signin[open]', { timeout: 15000 });
  await page.waitForTimeout(500);
  const pillBefore = await page.$eval('#fault-pill', (e) => ({ state: e.dataset.state, text: e.textContent }));
  check(pillBefore.state === 'unknown' && pillBefore.text === 'faults ?', `before a sign-in the fault pill is unknown, not "no fault" (${JSON.stringify(pillBefore)})`);
  const before = first.filter((r) => r.path !== '/api/health');
  check(before.length === 0, `before a sign-in the page asks nothing but /api/health (${JSON.stringify(before)})`);
  await page.fill('#signin-token', token);
  await page.check('#signin-remember');
  await page.click('#signin-submit');
  await page.waitForSelector('#signin:not([open])', { state: 'attached', timeout: 15000 });
  check(await until(() => READY.results(page), 15000), 'signed in, #/results/1 shows sweep #1');

  for (const [view, hash] of [['live', '#/live'], ['sweep', '#/sweep'], ['results', '#/results/1'], ['history', '#/history']]) {
    await page.goto(`${origin.url}${hash}`);
    const seen = watch(page);
    await page.reload();
    const ready = await until(() => READY[view](page), 15000);
    await page.waitForTimeout(1000);
    const refused = seen.filter((r) => r.status === 401);
    check(ready, `after F5 on ${hash} the view shows its data`);
    check((await dialogOpen(page)) === false, `after F5 on ${hash} no sign-in dialog is open`);
    check(refused.length === 0, `after F5 on ${hash} no request was refused 401 (${JSON.stringify(refused)}; ${seen.length} API answers)`);
  }

  // A results link in a new tab: the token remembered on this device signs it in.
  const tab = await ctx.newPage();
  const seen = watch(tab);
  await tab.goto(`${origin.url}#/results/1`);
  check(await until(() => READY.results(tab), 15000), 'a results link opened in a new tab shows sweep #1');
  await tab.waitForTimeout(1000);
  check((await dialogOpen(tab)) === false, 'the new tab opens no sign-in dialog');
  const refused = seen.filter((r) => r.status === 401);
  check(refused.length === 0, `the new tab sent nothing refused 401 (${JSON.stringify(refused)})`);
  check(pageErrors.length === 0, `no page errors (${pageErrors.join('; ')})`);
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  await tearDown({ browser, origin, daemon });
  log('done');
}
finish();
