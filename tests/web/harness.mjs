// Shared by the dashboard's end-to-end tests: the daemon, the page's origin, headless Chromium
// through playwright-core (from web/node_modules), checks and screenshots.
//
// Missing web/node_modules or web/dist: skip (exit 77) locally, fail when CI=true.
import { spawn } from 'node:child_process';
import { createRequire } from 'node:module';
import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import readline from 'node:readline';

export const SKIP = 77;

export function args() {
  const [bin, sourceDir, artifacts] = process.argv.slice(2);
  if (!bin || !sourceDir || !artifacts) {
    console.error('usage: node TEST.mjs path/to/synbench SOURCE_DIR ARTIFACT_DIR');
    process.exit(2);
  }
  fs.mkdirSync(artifacts, { recursive: true });
  return { bin: path.resolve(bin), sourceDir: path.resolve(sourceDir), artifacts: path.resolve(artifacts), webDir: path.resolve(sourceDir, 'web') };
}

export function skipOrFail(message) {
  if (process.env.CI === 'true' || process.env.CI === '1') {
    console.error(`FAIL (CI): ${message}`);
    process.exit(1);
  }
  console.log(`skip: ${message}`);
  process.exit(SKIP);
}

export function loadPlaywright(webDir) {
  if (!fs.existsSync(path.join(webDir, 'node_modules', 'playwright-core')))
    skipOrFail(`${webDir}/node_modules is absent: run "npm ci" in web/ (scripts/build.sh does)`);
  if (!fs.existsSync(path.join(webDir, 'dist', 'index.html')))
    skipOrFail(`${webDir}/dist is absent: run "npm run build" in web/ (scripts/build.sh does)`);
  const exe = process.env.CHROMIUM || '/usr/bin/chromium';
  if (!fs.existsSync(exe)) skipOrFail(`${exe} is absent: install Debian's chromium (scripts/install-deps.sh)`);
  const require = createRequire(path.join(webDir, 'package.json'));
  return { chromium: require('playwright-core').chromium, exe };
}

export async function launch(pw) {
  return pw.chromium.launch({
    executablePath: pw.exe,
    args: ['--headless=new', '--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
  });
}

// ---- checks ---------------------------------------------------------------------------------
const failures = [];
const t0 = Date.now();
export function log(...a) { console.log(`[${((Date.now() - t0) / 1000).toFixed(1)} s]`, ...a); }
export function check(cond, what) {
  if (cond) log('ok:', what);
  else { failures.push(what); log('FAIL:', what); }
  return cond;
}
export function finish() {
  if (failures.length) {
    console.log(`${failures.length} check(s) failed:\n  ${failures.join('\n  ')}`);
    process.exit(1);
  }
  log('all checks passed');
  process.exit(0);
}
// Waits for fn() to be truthy; returns its value or null after timeoutMs.
export async function until(fn, timeoutMs, stepMs = 200) {
  const end = Date.now() + timeoutMs;
  for (;;) {
    let v = null;
    try { v = await fn(); } catch { v = null; }
    if (v) return v;
    if (Date.now() > end) return null;
    await new Promise((r) => setTimeout(r, stepMs));
  }
}

export async function shot(page, artifacts, name) {
  const file = path.join(artifacts, `${name}.png`);
  await page.screenshot({ path: file, fullPage: false });
  log('screenshot', file);
  return file;
}

// ---- the daemon -----------------------------------------------------------------------------
export function tmpDir(prefix) { return fs.mkdtempSync(path.join(os.tmpdir(), prefix)); }

export async function startDaemon(bin, dataDir, { port = 0, webDir, extraArgs = [] } = {}) {
  const argv = ['serve', '--listen', `127.0.0.1:${port}`, '--data-dir', dataDir, ...extraArgs];
  if (webDir && (await helpMentions(bin, '--web-dir'))) argv.push('--web-dir', path.join(webDir, 'dist'));
  const proc = spawn(bin, argv, { stdio: ['ignore', 'pipe', 'pipe'] });
  let stderr = '';
  proc.stderr.on('data', (d) => { stderr += d; });
  const rl = readline.createInterface({ input: proc.stdout });
  const line = await new Promise((resolve) => {
    const timer = setTimeout(() => resolve(null), 20000);
    rl.once('line', (l) => { clearTimeout(timer); resolve(l); });
    proc.once('exit', () => { clearTimeout(timer); resolve(null); });
  });
  const m = /listening on (http:\/\/127\.0\.0\.1:(\d+))/.exec(line || '');
  if (!m) { proc.kill('SIGKILL'); throw new Error(`synbench serve did not start: ${line} ${stderr.slice(-500)}`); }
  rl.on('line', () => {});
  log(`daemon pid ${proc.pid} on ${m[1]}`);
  return { proc, url: m[1], port: Number(m[2]), stderr: () => stderr };
}

export async function stopDaemon(d, signal = 'SIGTERM') {
  if (d.proc.exitCode !== null) return d.proc.exitCode;
  const exited = new Promise((r) => d.proc.once('exit', (code) => r(code)));
  d.proc.kill(signal);
  const code = await Promise.race([exited, new Promise((r) => setTimeout(() => r('timeout'), 25000))]);
  if (code === 'timeout') { d.proc.kill('SIGKILL'); await exited; }
  return code;
}

// A test's end, whatever happened: the browser and the page's origin closed, the daemon sent
// SIGTERM and checked to exit 0 (its ordered stop and store close went well).
export async function tearDown({ browser, origin, daemon }) {
  await browser.close();
  await origin.stop();
  const code = await stopDaemon(daemon);
  check(code === 0, `the daemon exits 0 on SIGTERM (${code})`);
}

const helpCache = new Map();
async function helpMentions(bin, word) {
  if (!helpCache.has(bin)) {
    helpCache.set(bin, await new Promise((resolve) => {
      const p = spawn(bin, ['serve', '--help'], { stdio: ['ignore', 'pipe', 'pipe'] });
      let out = '';
      p.stdout.on('data', (d) => { out += d; });
      p.stderr.on('data', (d) => { out += d; });
      p.on('exit', () => resolve(out));
    }));
  }
  return helpCache.get(bin).includes(word);
}

export async function rest(base, method, p, token, body) {
  const res = await fetch(base + p, {
    method, headers: { ...(token ? { Authorization: `Bearer ${token}` } : {}), ...(body ? { 'Content-Type': 'application/json' } : {}) },
    body: body ? JSON.stringify(body) : undefined,
  });
  const text = await res.text();
  let json = null;
  try { json = JSON.parse(text); } catch { /* not JSON */ }
  return { status: res.status, json, text, type: res.headers.get('content-type') || '' };
}

// The page's origin: the daemon itself when it serves web/dist at /, else `vite preview`
// proxying /api and /ws to it (until the daemon's static files land). Returns {url, stop()}.
export async function pageOrigin(daemon, webDir) {
  const r = await rest(daemon.url, 'GET', '/').catch(() => null);
  if (r && r.status === 200 && r.type.includes('text/html') && r.text.includes('synbench')) {
    log('the daemon serves the dashboard at /');
    return { url: `${daemon.url}/`, served: true, stop: async () => {} };
  }
  log(`the daemon does not serve / (status ${r?.status}): vite preview proxies to it`);
  const port = await freePort();
  const proc = spawn(process.execPath, [path.join(webDir, 'node_modules', 'vite', 'bin', 'vite.js'), 'preview', '--host', '127.0.0.1', '--port', String(port), '--strictPort'],
    { cwd: webDir, env: { ...process.env, SYNBENCH_URL: daemon.url }, stdio: ['ignore', 'pipe', 'pipe'] });
  const url = `http://127.0.0.1:${port}/`;
  const ok = await until(async () => (await fetch(url)).ok, 20000);
  if (!ok) throw new Error('vite preview did not start');
  return { url, served: false, stop: async () => { proc.kill('SIGTERM'); } };
}

export function freePort() {
  return new Promise((resolve, reject) => {
    const s = net.createServer();
    s.on('error', reject);
    s.listen(0, '127.0.0.1', () => { const { port } = s.address(); s.close(() => resolve(port)); });
  });
}

// ---- the page -------------------------------------------------------------------------------
export async function signIn(page, token) {
  await page.waitForSelector('#signin[open]', { timeout: 15000 });
  await page.fill('#signin-token', token);
  await page.click('#signin-submit');
  await page.waitForSelector('#signin:not([open])', { state: 'attached', timeout: 15000 });
}

export const text = (page, sel) => page.$eval(sel, (e) => e.textContent.trim()).catch(() => '');
export const attr = (page, sel, a) => page.$eval(sel, (e, a) => e.getAttribute(a), a).catch(() => null);
