// The dashboard's safety controls and page shell (issue 25, part A) in headless Chromium, on
// `synbench serve --bench` over Modbus TCP to `synbench emulate`, the drives' registers read from
// the far side (far_side.mjs). Safety first:
//  1. Esc in the help dialog closes it and does not E-stop; the dialog's own E-STOP button works
//     by mouse while the (modal) dialog is open; Esc in a form field still E-stops.
//  2. E-STOP stays red with white text on hover, focus and active: contrast >= 4.5:1.
//  3. An E-stop zeroes the held setpoints (its own answer says so), the form shows 0, and after
//     reset + Enable the drives' speed and torque setpoint registers read 0.
//  4. A viewer may E-stop; the events name the viewer's token id and role; reset stays operator's.
//  5. An E-stop the daemon does not answer (SIGSTOP) raises a persistent role=alert banner within
//     ~1.5 s, cleared by dismissing it or by a status that shows the bench stopped.
//  6. Before sign-in the page says "signed out", not offline.
//  8. At 390x844 no view is wider than the screen, the sign-in dialog fits, E-STOP stays visible.
//  9. The first load moves under 300 KB (gzip); the figure is printed.
// 10. Tab reaches the top bar and the dialogs' controls, with a visible focus ring.
// (7, the daemon restart, is in restart.mjs.) Screenshots: ARTIFACT_DIR/safety-*.png.
//
// usage: node safety.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import {
  args, loadPlaywright, launch, check, finish, until, shot, tmpDir, startDaemon, stopDaemon, pageOrigin,
  signIn, text, attr, log, rest,
} from './harness.mjs';
import { ModbusTcp, startEmulator, writeBenchConfig, STATES } from './far_side.mjs';

const { bin, webDir, artifacts } = args();
const pw = loadPlaywright(webDir);
const tmp = tmpDir('synbench-web-safety-');
const emu = await startEmulator(bin, path.join(tmp, 'emulate.log'), ['--watchdog-timeout-ms', '3000', '--duration-s', '600']);
const far = await ModbusTcp.connect(emu.port);
const dataDir = path.join(tmp, 'data');
const daemon = await startDaemon(bin, dataDir, { webDir, extraArgs: ['--bench', writeBenchConfig(path.join(tmp, 'bench.json'), emu.port)] });
const origin = await pageOrigin(daemon, webDir);
const token = fs.readFileSync(path.join(dataDir, 'operator.token'), 'utf8').trim();
const viewer = execFileSync(bin, ['token', 'create', '--role', 'viewer', '--data-dir', dataDir], { encoding: 'utf8' }).trim();
const browser = await launch(pw);
const status = async () => (await rest(daemon.url, 'GET', '/api/bench/status', token)).json;
const phase = async () => (await status())?.supervisor?.phase;
const describe = (st) => st.map(([s, f]) => `${STATES[s] ?? s}/${f}`).join(', ');

// WCAG 2 contrast of two computed colours ("rgb(r, g, b)").
function contrast(fg, bg) {
  const lum = (c) => {
    const [r, g, b] = c.match(/\d+(\.\d+)?/g).slice(0, 3).map(Number).map((v) => {
      const s = v / 255;
      return s <= 0.03928 ? s / 12.92 : ((s + 0.055) / 1.055) ** 2.4;
    });
    return 0.2126 * r + 0.7152 * g + 0.0722 * b;
  };
  const [a, b] = [lum(fg), lum(bg)].sort((x, y) => y - x);
  return (a + 0.05) / (b + 0.05);
}
const colours = (page, sel) => page.$eval(sel, (e) => { const c = getComputedStyle(e); return { fg: c.color, bg: c.backgroundColor, outline: c.outlineStyle + ' ' + c.outlineWidth }; });

try {
  // ---- 6 and 9: the first load, signed out ----------------------------------------------------
  const ctx = await browser.newContext({ viewport: { width: 1280, height: 800 } });
  const page = await ctx.newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(String(e)));
  const cdp = await ctx.newCDPSession(page);
  await cdp.send('Network.enable');
  await cdp.send('Network.setCacheDisabled', { cacheDisabled: true });
  let transferred = 0;
  const encodings = new Map();
  cdp.on('Network.responseReceived', (e) => encodings.set(e.requestId, `${e.response.url} ${e.response.headers['content-encoding'] || e.response.headers['Content-Encoding'] || 'identity'}`));
  cdp.on('Network.loadingFinished', (e) => { transferred += e.encodedDataLength; });
  await page.goto(origin.url, { waitUntil: 'networkidle' });
  await page.waitForSelector('#signin[open]');
  log(`first load: ${(transferred / 1024).toFixed(1)} KB transferred (${[...encodings.values()].join('; ')})`);
  check(transferred > 0 && transferred < 300 * 1024, `the first load moves under 300 KB: ${(transferred / 1024).toFixed(1)} KB`);
  check([...encodings.values()].some((v) => /echarts.*\.js gzip$/.test(v)), 'the chart bundle comes gzip-encoded');
  await cdp.detach();
  check((await text(page, '#conn')) === 'signed out' && (await attr(page, '#conn', 'data-state')) === 'signedout',
    `before sign-in the connection pill says signed out (${await text(page, '#conn')})`);
  const unreachable = await page.evaluate(() => getComputedStyle(document.querySelector('.topbar'), '::after').content);
  check(unreachable === 'none' || unreachable === '', `no "daemon is unreachable" banner before sign-in (${unreachable})`);
  check(await page.$eval('#conn', (e) => getComputedStyle(e).backgroundColor !== 'rgb(179, 38, 30)'), 'the signed-out pill is not red');
  await shot(page, artifacts, 'safety-1-signed-out');
  await signIn(page, token);
  check(await until(async () => ['connected', 'polling'].includes(await attr(page, '#conn', 'data-state')), 15000), 'signed in: connected');
  check(await until(async () => (await status())?.synrm, 10000), 'the daemon reads the emulated drives');

  // ---- 2: E-STOP contrast on hover, focus and active ------------------------------------------
  await page.mouse.move(5, 700);
  const rest0 = await colours(page, '#estop');
  check(contrast(rest0.fg, rest0.bg) >= 4.5, `E-STOP at rest: ${rest0.fg} on ${rest0.bg}, ${contrast(rest0.fg, rest0.bg).toFixed(2)}:1`);
  await page.hover('#estop');
  const hover = await colours(page, '#estop');
  check(contrast(hover.fg, hover.bg) >= 4.5 && /rgb\((1[5-9]\d|2\d\d), \d{1,2}, /.test(hover.bg),
    `E-STOP on hover stays red with white text: ${hover.fg} on ${hover.bg}, ${contrast(hover.fg, hover.bg).toFixed(2)}:1`);
  const box = await (await page.$('#estop')).boundingBox();
  await page.mouse.down();
  const active = await colours(page, '#estop');
  await page.mouse.move(5, 700); // released elsewhere: no click, no E-stop
  await page.mouse.up();
  check(contrast(active.fg, active.bg) >= 4.5 && /rgb\((1[5-9]\d|2\d\d), \d{1,2}, /.test(active.bg),
    `E-STOP while pressed: ${active.fg} on ${active.bg}, ${contrast(active.fg, active.bg).toFixed(2)}:1`);
  check(box.width > 0, 'E-STOP has a box');

  // ---- 10: Tab through the top bar, a visible focus ring ----------------------------------------
  await page.focus('a.skip'); // the first stop of the page's Tab order
  const reached = ['skip'];
  let estopFocus = null;
  for (let i = 0; i < 14; ++i) {
    await page.keyboard.press('Tab');
    const f = await page.evaluate(() => {
      const e = document.activeElement;
      const c = getComputedStyle(e);
      return { id: e.id || e.dataset.nav || e.className, outline: `${c.outlineStyle} ${c.outlineWidth}`, fg: c.color, bg: c.backgroundColor };
    });
    reached.push(f.id);
    if (f.id === 'estop') { estopFocus = f; break; }
  }
  check(['live', 'sweep', 'results', 'history', 'signout', 'help-open', 'estop'].every((id) => reached.includes(id)),
    `Tab reaches the views, sign-out, help and E-STOP (${reached.join(' > ')})`);
  check(estopFocus && /solid [3-9]px/.test(estopFocus.outline), `the focused E-STOP has a visible focus ring (${estopFocus?.outline})`);
  check(estopFocus && contrast(estopFocus.fg, estopFocus.bg) >= 4.5, `E-STOP focused: ${estopFocus?.fg} on ${estopFocus?.bg}`);
  await shot(page, artifacts, 'safety-2-estop-focused');

  // ---- 1: the help dialog: Esc closes it, no E-stop; its E-STOP button works by mouse --------
  await page.evaluate(() => document.activeElement?.blur());
  await page.keyboard.press('?');
  check(await until(() => page.$('#help[open]'), 2000), 'the help dialog opens with ?');
  const inDialog = [];
  for (let i = 0; i < 3; ++i) { await page.keyboard.press('Tab'); inDialog.push(await page.evaluate(() => { const e = document.activeElement; return `${e.closest('dialog')?.id}:${e.tagName === 'BUTTON' ? e.textContent.trim() : e.tagName}`; })); }
  check(inDialog.some((t) => t === 'help:Close') && inDialog.some((t) => t.startsWith('help:E-STOP')), `Tab in the help dialog reaches Close and E-STOP (${inDialog.join(', ')})`);
  await page.keyboard.press('Escape');
  await page.waitForTimeout(600);
  check(!(await page.$('#help[open]')), 'Esc closes the help dialog');
  check((await phase()) === 'normal', `... and does not E-stop (phase ${await phase()})`);
  await page.click('#help-open');
  check(await until(() => page.$('#help[open]'), 2000), 'the Help button opens the dialog');
  const reachable = await page.$eval('#help .estop', (b) => {
    const r = b.getBoundingClientRect();
    return !b.disabled && document.elementFromPoint(r.x + r.width / 2, r.y + r.height / 2) === b;
  });
  check(reachable, 'while the dialog is open its E-STOP button is enabled and on top (reachable by mouse)');
  await shot(page, artifacts, 'safety-3-help-estop');
  await page.click('#help .estop');
  check(await until(async () => (await phase()) === 'estopped', 3000), 'the dialog\'s E-STOP stops the bench');
  await page.click('#help button.primary');
  check(!(await page.$('#help[open]')), 'Close closes the dialog');
  check((await rest(daemon.url, 'POST', '/api/bench/reset', token, {})).status === 200, 'reset over REST');

  // ---- 3: setpoints after an E-stop and a reset, from the far side ----------------------------
  await page.fill('#setpoints-form [name=speed_rpm]', '900');
  await page.fill('#setpoints-form [name=load_Nm]', '2');
  await page.fill('#setpoints-form [name=angle_deg]', '55');
  await page.click('#setpoints-form button[type=submit]');
  check(await until(async () => (await status()).setpoints.speed_rpm === 900, 5000), 'setpoints 900 rpm, 2 N m applied from the form');
  await page.click('#btn-enable');
  check(await until(async () => (await far.speedRpm()) > 100, 15000), `the drive turns (far side: ${(await far.speedRpm()).toFixed(0)} rpm)`);
  check(Math.abs((await far.speedSetpointRpm()) - 900) < 1, `far side: speed setpoint register ${await far.speedSetpointRpm()} rpm`);
  // Esc in an edit field undoes the edit, no E-stop; a second Esc within a second E-stops.
  await page.focus('#setpoints-form [name=speed_rpm]');
  await page.fill('#setpoints-form [name=speed_rpm]', '1234');
  let estops = 0;
  page.on('request', (r) => { if (r.url().endsWith('/api/bench/estop')) estops++; });
  await page.keyboard.press('Escape');
  await page.waitForTimeout(1300);
  check((await page.inputValue('#setpoints-form [name=speed_rpm]')) === '900', `Esc in a field puts back its value (${await page.inputValue('#setpoints-form [name=speed_rpm]')})`);
  check(estops === 0 && (await phase()) === 'normal' && (await far.states()).every(([s]) => s === 1),
    `... and is no E-stop: phase ${await phase()}, far side both running (${describe(await far.states())})`);
  await page.keyboard.press('Escape'); // more than a second later: undoes again, still no E-stop
  await page.waitForTimeout(300);
  check(estops === 0 && (await phase()) === 'normal', 'one Esc a second later in the field is again no E-stop');
  const answer = page.waitForResponse((r) => r.url().endsWith('/api/bench/estop') && r.request().method() === 'POST', { timeout: 5000 });
  await page.keyboard.press('Escape'); // the second within a second
  const st = await (await answer).json();
  check(st.supervisor.phase === 'estopped', 'Esc twice within a second in a form field E-stops');
  check(st.setpoints.speed_rpm === 0 && st.setpoints.load_Nm === 0 && st.setpoints.angle_deg === 55,
    `the E-stop's own answer shows the setpoints zeroed (${JSON.stringify(st.setpoints)})`);
  check(st.supervisor.disable.synrm.setpoint_zeroed && st.supervisor.disable.load.setpoint_zeroed,
    `... and setpoint_zeroed for both drives (${st.supervisor.disable.synrm.setpoint_zeroed}, ${st.supervisor.disable.load.setpoint_zeroed})`);
  check(await until(async () => (await page.inputValue('#setpoints-form [name=speed_rpm]')) === '0'
    && (await page.inputValue('#setpoints-form [name=load_Nm]')) === '0', 3000), 'the Live form shows the zeroed setpoints');
  check(await until(async () => (await far.states()).every(([s]) => s !== 1), 3000), `far side: both drives stopped (${describe(await far.states())})`);
  check((await far.speedSetpointRpm()) === 0 && (await far.torqueSetpointNm()) === 0, 'far side: speed and torque setpoint registers read 0 after the E-stop');
  await shot(page, artifacts, 'safety-4-estopped-zeroed');
  // Reset from the page (refused while a drive still reads running: pressed again until it takes).
  check(await until(async () => { await page.click('#btn-reset'); await page.waitForTimeout(300); return (await phase()) !== 'estopped'; }, 15000, 500),
    `reset from the page (phase ${await phase()})`);
  const coasting = Math.abs(await far.speedRpm());
  await page.click('#btn-enable');
  check(await until(async () => (await far.states()).every(([s]) => s === 1), 5000), `Enable: both drives run (${describe(await far.states())})`);
  await page.waitForTimeout(1000);
  const [sp, tq, spd] = [await far.speedSetpointRpm(), await far.torqueSetpointNm(), await far.speedRpm()];
  check(sp === 0 && tq === 0, `after reset + Enable, far side: speed setpoint ${sp} rpm, torque setpoint ${tq} N m`);
  check(Math.abs(spd) <= coasting + 5 && Math.abs(spd) < 850, `... and the drive does not go back to 900 rpm (${coasting.toFixed(0)} -> ${spd.toFixed(0)} rpm)`);
  await page.click('#btn-disable');
  check(await until(async () => (await far.states()).every(([s]) => s === 0), 10000), 'ordered stop: both drives disabled');

  // ---- 4: a viewer E-stops ----------------------------------------------------------------------
  const vctx = await browser.newContext({ viewport: { width: 1280, height: 800 } });
  const vpage = await vctx.newPage();
  await vpage.goto(origin.url);
  await signIn(vpage, viewer);
  check(await until(async () => (await text(vpage, '#role-pill')).startsWith('viewer'), 5000), 'signed in as a viewer');
  const viewerId = await vpage.evaluate(() => window.synbench.callerId);
  check(await vpage.$eval('#estop', (e) => !e.disabled), "the viewer's E-STOP is enabled");
  check(await vpage.$eval('#btn-reset', (e) => e.disabled) && await vpage.$eval('#btn-enable', (e) => e.disabled), 'the viewer cannot reset or enable');
  await vpage.click('#estop');
  check(await until(async () => (await text(vpage, '#bench-pill')) === 'E-STOPPED', 3000), 'the viewer sees the bench E-STOPPED');
  check(await until(async () => (await text(vpage, '#events')).includes(`E-stop by ${viewerId} (viewer)`), 3000),
    `the events name the viewer who pressed it (${viewerId})`);
  check((await status()).supervisor.trip.detail === `E-stop by ${viewerId} (viewer)`, 'the trip detail names the viewer');
  check((await far.states()).every(([s]) => s !== 1), `far side: no drive runs (${describe(await far.states())})`);
  check((await rest(daemon.url, 'POST', '/api/bench/reset', viewer, {})).status === 403, 'a viewer still gets 403 on reset');
  await shot(vpage, artifacts, 'safety-5-viewer-estop');
  await vctx.close();
  check(await until(async () => (await rest(daemon.url, 'POST', '/api/bench/reset', token, {})).status === 200, 5000), 'the operator resets');

  // ---- 5: the daemon does not answer an E-stop --------------------------------------------------
  check(await until(async () => (await phase()) !== 'estopped', 5000), `the bench is reset (${await phase()})`);
  daemon.proc.kill('SIGSTOP');
  const t0 = Date.now();
  await page.click('#estop');
  const shown = await until(() => page.$('#estop-failed:not([hidden])'), 4000, 50);
  const took = Date.now() - t0;
  check(shown && took < 3500, `the failed E-stop banner shows within ${took} ms`);
  check((await text(page, '#estop-failed')).startsWith('E-stop NOT confirmed: the daemon did not answer. Use the hardware emergency stop.'),
    `its words (${await text(page, '#estop-failed')})`);
  check((await attr(page, '#estop-failed', 'role')) === 'alert', 'the banner is role=alert');
  const banner = await page.$eval('#estop-failed', (e) => ({ top: e.getBoundingClientRect().top, bg: getComputedStyle(e).backgroundColor }));
  check(banner.top < 200 && /rgb\(1[0-9]{2}|rgb\(2[0-9]{2}/.test(banner.bg), `it is red, at the top (${banner.bg}, top ${banner.top})`);
  await shot(page, artifacts, 'safety-6-estop-not-confirmed');
  await page.waitForTimeout(3000);
  check(await page.$('#estop-failed:not([hidden])'), 'it stays (not a toast)');
  await page.click('#estop-failed-dismiss');
  check(await page.$('#estop-failed[hidden]'), 'Dismiss hides it');
  await page.click('#estop');
  check(await until(() => page.$('#estop-failed:not([hidden])'), 3000, 50), 'a second unanswered press shows it again');
  daemon.proc.kill('SIGCONT');
  check(await until(async () => (await phase()) === 'estopped', 10000), 'resumed, the daemon acts on the queued E-stop');
  check(await until(() => page.$('#estop-failed[hidden]'), 10000), 'a status showing the bench stopped clears the banner');
  check(await until(async () => (await rest(daemon.url, 'POST', '/api/bench/reset', token, {})).status === 200, 10000), 'reset');

  // ---- 8: 390 px wide ------------------------------------------------------------------------------
  const nctx = await browser.newContext({ viewport: { width: 390, height: 844 } });
  const npage = await nctx.newPage();
  await npage.goto(origin.url);
  await npage.waitForSelector('#signin[open]');
  const dbox = await npage.$eval('#signin', (d) => { const r = d.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; });
  check(dbox[0] >= 0 && dbox[1] >= 0 && dbox[2] <= 390 && dbox[3] <= 844, `at 390x844 the sign-in dialog fits (${dbox.map(Math.round).join(', ')})`);
  await shot(npage, artifacts, 'safety-7-narrow-signin');
  await signIn(npage, token);
  for (const [key, view] of [['1', 'live'], ['2', 'sweep'], ['3', 'results'], ['4', 'history']]) {
    await npage.keyboard.press(key);
    await npage.waitForTimeout(800);
    const w = await npage.evaluate(() => document.scrollingElement.scrollWidth);
    const e = await npage.$eval('#estop', (b) => { const r = b.getBoundingClientRect(); return r.right <= 390 && r.bottom <= 844 && r.width > 0; });
    check(w <= 390 && e, `at 390 px the ${view} view is ${w} px wide, E-STOP visible`);
    await shot(npage, artifacts, `safety-8-narrow-${view}`);
  }
  await nctx.close();
  check(pageErrors.length === 0, `no uncaught errors on the page (${pageErrors.join('; ')})`);
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  try { daemon.proc.kill('SIGCONT'); } catch { /* gone */ }
  await browser.close();
  await origin.stop();
  far.close();
  const code = await stopDaemon(daemon);
  check(code === 0, `the daemon exits 0 on SIGTERM (${code})`);
  await emu.stop();
  log('done');
}
finish();
