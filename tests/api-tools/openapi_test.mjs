// The daemon's OpenAPI document as API tools see it (issue 42, item 3):
// 1. Redocly CLI (pinned in tests/api-tools/package-lock.json) lints GET /api/openapi.json with
//    its recommended ruleset: no error; the warnings are printed (the document names no license:
//    the project has none to name yet);
// 2. a client generated from the document at run time (openapi-client-axios: one method per
//    operationId) runs the example script's calls (examples/scripted_sweep.py): health, whoami,
//    the plan's estimate, create, start, follow the sweep to `completed`, its points and analysis,
//    all through the generated methods; the numbers agree with the same routes read directly.
//
// usage: node openapi_test.mjs path/to/synbench SOURCE_DIR
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { check, finish, log, rest, startDaemon, stopDaemon, tmpDir } from '../web/harness.mjs';

const [bin] = process.argv.slice(2);
const here = path.dirname(fileURLToPath(import.meta.url));
const redocly = path.join(here, 'node_modules', '@redocly', 'cli', 'bin', 'cli.js');
if (!fs.existsSync(redocly)) {
  // scripts/test.sh installs them (npm ci in tests/api-tools); CI must have them.
  console.log('SKIP: tests/api-tools/node_modules is missing (npm ci in tests/api-tools)');
  process.exit(process.env.CI === 'true' ? 1 : 77);
}
const { OpenAPIClientAxios } = await import('openapi-client-axios');

const dir = tmpDir('synbench-openapi-');
const daemon = await startDaemon(bin, path.join(dir, 'data'));
const token = fs.readFileSync(path.join(dir, 'data', 'operator.token'), 'utf8').trim();
try {
  const doc = (await rest(daemon.url, 'GET', '/api/openapi.json')).json;
  const file = path.join(dir, 'openapi.json');
  fs.writeFileSync(file, JSON.stringify(doc));
  const ids = Object.values(doc.paths).flatMap((m) => Object.values(m).map((op) => op.operationId));
  check(new Set(ids).size === ids.length && ids.every((id) => /^[a-z][A-Za-z0-9]*$/.test(id)),
    `${ids.length} operations, each with its own URL-safe operationId (${ids.slice(0, 4).join(', ')}, ...)`);

  // ---- 1. the linter ----
  const lint = spawnSync(process.execPath, [redocly, 'lint', '--extends', 'recommended', '--format', 'json', file], { encoding: 'utf8' });
  let problems = [];
  try { problems = JSON.parse(lint.stdout).problems; } catch { check(false, `the linter's JSON output: ${lint.stdout.slice(0, 300)} ${lint.stderr.slice(0, 300)}`); }
  const errors = problems.filter((p) => p.severity === 'error');
  const warnings = problems.filter((p) => p.severity === 'warn');
  for (const p of problems) log(`redocly ${p.severity}: ${p.ruleId}: ${p.message}`);
  check(lint.status === 0 && errors.length === 0, `Redocly CLI's recommended rules: ${errors.length} errors, ${warnings.length} warnings (exit ${lint.status})`);
  check(warnings.every((w) => w.ruleId === 'info-license'), `the only warning is the missing license (${warnings.map((w) => w.ruleId).join(', ')})`);

  // ---- 2. a generated client runs the example script's calls ----
  const api = new OpenAPIClientAxios({ definition: doc, withServer: { url: daemon.url },
    axiosConfigDefaults: { headers: { Authorization: `Bearer ${token}` }, timeout: 30000 } });
  const client = await api.init();
  const health = (await client.getHealth()).data;
  const me = (await client.getWhoami()).data;
  check(health.status === 'ok' && me.role === 'operator', `getHealth, getWhoami: ${health.version}, ${me.role}`);
  const plan = { name: 'generated client', window_s: 0.2,
    dimensions: { speed_rpm: [300, 600], load_Nm: [1], angle_deg: [48, 52, 56], configurations: [{ estimator: 'encoder', pwm: 'capwm' }] } };
  const estimate = (await client.postSweepsEstimate(null, plan)).data;
  check(estimate.points === 6 && estimate.duration_s > 0, `postSweepsEstimate: ${estimate.points} points, ${estimate.duration_s?.toFixed(0)} s`);
  const created = await client.postSweeps(null, plan);
  const id = created.data.id;
  check(created.status === 201 && Number.isInteger(id), `postSweeps: 201, sweep ${id}`);
  check((await client.postSweepStart({ id })).status < 300, 'postSweepStart');
  let sweep;
  for (let i = 0; i < 300; i++) {
    sweep = (await client.getSweep({ id })).data;
    if (!['created', 'running', 'paused'].includes(sweep.state)) break;
    await new Promise((r) => setTimeout(r, 500));
  }
  check(sweep.state === 'completed' && sweep.points_stored === 6, `getSweep: ${sweep.state}, ${sweep.points_stored} points`);
  const points = (await client.getSweepPoints({ id })).data;
  const direct = (await rest(daemon.url, 'GET', `/api/sweeps/${id}/points`, token)).json;
  check(points.length === 6 && JSON.stringify(points) === JSON.stringify(direct), `getSweepPoints: the 6 points the route gives (η ${points.map((p) => p.efficiency?.toFixed(3)).join(', ')})`);
  const analysis = (await client.getSweepAnalysis({ id })).data;
  const curves = analysis.curves?.entries || [];
  check(curves.length === 2 && curves.every((c) => c.mtpa.angle_deg > 40 && c.mtpa.angle_deg < 60),
    `getSweepAnalysis: MTPA at ${curves.map((c) => `${c.speed_rpm} rpm ${c.mtpa.angle_deg.toFixed(1)} deg`).join(', ')}`);
  const status = (await client.getBenchStatus()).data;
  check(status.enabled === false && status.supervisor.phase === 'normal', `getBenchStatus after the sweep: enabled ${status.enabled}, ${status.supervisor.phase}`);
} catch (e) {
  check(false, `unexpected error: ${e.stack || e}`);
} finally {
  const code = await stopDaemon(daemon);
  check(code === 0, `the daemon exits 0 on SIGTERM (${code})`);
  fs.rmSync(dir, { recursive: true, force: true });
}
finish();
