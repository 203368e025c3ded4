// synbench dashboard: sign-in, the live link, routing between the four views, the always-visible
// E-stop (any signed-in role; a loud banner when the daemon does not confirm it) and the keyboard
// shortcuts. State shared by the views lives in `app`.
import './style.css';
import { api, setToken, setUnauthorizedHandler, ApiError } from './api.js';
import { Link, faultText } from './link.js';
import { renderTripControls } from './trip.js';
import { LiveView } from './views/live.js';
import { SweepView } from './views/sweep.js';
import { ResultsView } from './views/results.js';
import { HistoryView } from './views/history.js';

const $ = (s) => document.querySelector(s);
const TOKEN_KEY = 'synbench.token';

class App {
  constructor() {
    this.role = null;
    this.callerId = null;
    this.status = null;          // last GET /api/bench/status (or WS state push)
    this.sweeps = [];            // run history
    this.listeners = new Map();
    this.link = null;
    this.view = 'live';
    this.instance = null;        // the daemon's per-start id (GET /api/health, the socket's hello)
  }

  on(ev, fn) { (this.listeners.get(ev) || this.listeners.set(ev, []).get(ev)).push(fn); }
  emit(ev, arg) { for (const fn of this.listeners.get(ev) || []) { try { fn(arg); } catch (e) { console.error(e); } } }

  get isOperator() { return this.role === 'operator'; }

  toast(text, bad = false) {
    const t = $('#toast');
    t.textContent = text;
    t.classList.toggle('bad', bad);
    t.classList.add('show');
    clearTimeout(this.toastTimer);
    this.toastTimer = setTimeout(() => t.classList.remove('show'), bad ? 6000 : 2500);
  }

  // Runs an operator command (over the socket when up, else REST) and reports errors.
  async command(method, path, body, okText) {
    try {
      const r = await this.link.request(method, path, body);
      if (okText) this.toast(okText);
      if (r && r.t_s !== undefined && r.supervisor) this.setStatus(r);
      return r;
    } catch (e) {
      // In an operator's words: the action, then the daemon's reason (never a route).
      this.toast(`${actionName(method, path)}: ${e.message}`, true);
      throw e;
    }
  }

  setStatus(st) {
    this.status = st;
    this.emit('status', st);
    renderBenchPills(st);
    renderTripControls(st, this.isOperator);
    // A failed E-stop's banner stays until the daemon itself says the bench is stopped.
    if (st.supervisor?.phase === 'estopped' && !st.enabled) $('#estop-failed').hidden = true;
  }

  // A new daemon instance (a restart): what the page showed of the old one's events goes.
  noteInstance(id) {
    if (!id) return;
    if (this.instance && id !== this.instance) this.emit('daemon-restarted', id);
    this.instance = id;
  }

  async refreshSweeps() {
    try {
      this.sweeps = await api('GET', '/api/sweeps');
      this.emit('sweeps', this.sweeps);
    } catch (e) { if (e.status !== 401) console.warn('sweeps', e.message); }
  }

  async refreshAll() {
    try { this.setStatus(await api('GET', '/api/bench/status')); } catch { /* link reports offline */ }
    await this.refreshSweeps();
    this.emit('refresh');
  }
}

// A command's name as the page's controls call it, for its error message.
function actionName(method, path) {
  const names = {
    '/api/bench/enable': 'Enable / ordered stop', '/api/bench/setpoints': 'Apply setpoints', '/api/bench/reset': 'Reset trip',
    '/api/bench/mode': 'Apply estimator and PWM', '/api/bench/lock': method === 'DELETE' ? 'Release lock' : 'Take control lock',
    '/api/bench/estop': 'E-stop', '/api/sweeps': 'Create sweep',
  };
  if (names[path]) return names[path];
  const m = /^\/api\/sweeps\/(\d+)\/(\w+)$/.exec(path);
  if (m) return `Sweep #${m[1]}: ${m[2] === 'start' ? 'start / continue' : m[2]}`;
  return 'The daemon refused';
}

export const app = new App();
window.synbench = app; // for the end-to-end tests and the console

// ---- indicators -------------------------------------------------------------------------------
function renderConn(state) {
  const el = $('#conn');
  el.dataset.state = state;
  el.textContent = { connected: 'connected', polling: 'connected (REST polling)', connecting: 'connecting…', offline: 'offline, reconnecting…', signedout: 'signed out' }[state] || state;
  document.body.dataset.conn = state;
  if (state === 'offline') {
    const b = $('#bench-pill');
    b.dataset.state = 'unknown';
    b.textContent = 'bench ?';
    const f = $('#fault-pill');
    f.dataset.state = 'unknown';
    f.textContent = 'faults ?';
  }
}

function renderBenchPills(st) {
  if (document.body.dataset.conn === 'offline') return;
  const b = $('#bench-pill');
  const f = $('#fault-pill');
  const phase = st.supervisor?.phase;
  let state = 'disabled', text = 'bench disabled';
  if (phase === 'estopped') { state = 'estopped'; text = 'E-STOPPED'; }
  else if (st.stopping || phase === 'stopping_load' || phase === 'stopping_speed') { state = 'stopping'; text = 'stopping'; }
  else if (st.sweep && ['running', 'pausing', 'paused', 'stopping'].includes(st.sweep.state)) { state = 'running'; text = `sweep ${st.sweep.state}`; }
  else if (st.enabled) { state = 'running'; text = 'bench enabled'; }
  else if (!st.synrm) { state = 'bad'; text = 'link down'; }
  b.dataset.state = state;
  b.textContent = text;
  // A drive the daemon could not read: why, in the daemon's words (the last read's error).
  const unread = [['SynRM drive', st.synrm_error], ['load drive', st.load_error]].filter(([, e]) => e);
  b.title = unread.map(([d, e]) => `${d} not read: ${e}`).join('\n');
  document.body.dataset.bench = state;
  const trip = st.supervisor?.trip;
  const alarm = st.supervisor?.alarm;
  const faulted = [st.synrm, st.load].find((d) => d?.fault && d.fault !== 'none');
  const driveFault = faulted && faultText(faulted.fault, faulted.fault_code_raw);
  // A stop that did not take: as loud as the page can be, until a reset finds the drives stopped.
  const banner = $('#alarm-banner');
  banner.hidden = !alarm;
  banner.textContent = alarm ? `ALARM: ${alarm.detail}. The drives' own watchdogs are the second line `
    + `(heartbeats ${st.heartbeats === false ? 'stopped' : 'still sent'}): check the bench before anything else.` : '';
  document.body.classList.toggle('alarm', !!alarm);
  if (alarm) { f.dataset.state = 'tripped'; f.textContent = 'ALARM: drive not stopped'; f.title = alarm.detail; }
  else if (trip) { f.dataset.state = 'tripped'; f.textContent = `tripped: ${faultText(trip.fault, trip.fault_code_raw)}`; f.title = trip.detail || ''; }
  else if (driveFault) { f.dataset.state = 'bad'; f.textContent = `fault: ${driveFault}`; }
  // The drive's lock flag holds until a setpoint change: true of a running drive, stale for a
  // stopped one (it runs on no estimator at all), so it is shown only while the SynRM runs.
  else if (st.synrm?.lock_lost && st.synrm.state === 'running') {
    f.dataset.state = 'warn'; f.textContent = 'lock lost: on the encoder';
    f.title = 'the estimator left the encoder angle; the drive runs on the encoder until the speed or angle setpoint changes';
  } else if (st.synrm?.voltage_limited && st.synrm.state === 'running') { f.dataset.state = 'warn'; f.textContent = 'voltage limited'; }
  else { f.dataset.state = 'ok'; f.textContent = 'no fault'; }
}

function renderRole() {
  const r = $('#role-pill');
  r.dataset.state = app.role || 'none';
  r.textContent = app.role === 'operator' ? 'operator' : app.role === 'viewer' ? 'viewer · read-only' : 'signed out';
  r.title = app.role ? `${app.role}${app.callerId ? ` (${app.callerId})` : ''}` : 'Not signed in';
  r.hidden = !app.role; // signed out: the connection pill says so once
  $('#signout').hidden = !app.role;
  document.body.classList.toggle('role-viewer', app.role === 'viewer');
  document.body.classList.toggle('role-operator', app.role === 'operator');
  for (const el of document.querySelectorAll('.operator-only button, .operator-only input, .operator-only select'))
    el.disabled = app.role !== 'operator';
  // Every signed-in role may E-stop (the daemon records who did); only operators command.
  for (const el of document.querySelectorAll('.estop')) {
    el.disabled = !app.role;
    el.title = app.role ? 'Emergency stop: both drives disabled at once, latched until reset (key: Esc; in an edit field Esc twice)' : 'E-stop needs a sign-in';
  }
  app.emit('role', app.role);
}

// ---- sign-in ----------------------------------------------------------------------------------
async function whoami() {
  try {
    return await api('GET', '/api/whoami', undefined, { quiet401: true });
  } catch (e) {
    if (e.status !== 404 && e.status !== 405) throw e;
  }
  // Older daemon without /api/whoami: validate with a viewer route, then tell operator from
  // viewer by releasing the control lock (viewer: 403; operator: 200, or 409 when another holds it).
  await api('GET', '/api/bench/status', undefined, { quiet401: true });
  try {
    await api('DELETE', '/api/bench/lock', undefined, { quiet401: true });
    return { role: 'operator', id: null };
  } catch (e) {
    if (e.status === 403) return { role: 'viewer', id: null };
    if (e.status === 409) return { role: 'operator', id: null };
    throw e;
  }
}

function storedToken() { return sessionStorage.getItem(TOKEN_KEY) || localStorage.getItem(TOKEN_KEY); }

async function signIn(token, remember) {
  setToken(token);
  const me = await whoami();
  noteHealth();
  app.role = me.role;
  app.callerId = me.id;
  sessionStorage.setItem(TOKEN_KEY, token);
  if (remember) localStorage.setItem(TOKEN_KEY, token); else if (remember === false) localStorage.removeItem(TOKEN_KEY);
  renderRole();
  startLink();
  await app.refreshAll();
  route(); // the view shown since the page loaded now reads its data, with the token
}

function showSignIn(message = '') {
  const d = $('#signin');
  $('#signin-error').textContent = message;
  if (!d.open) d.showModal();
  $('#signin-token').focus();
}

function signOut() {
  sessionStorage.removeItem(TOKEN_KEY);
  localStorage.removeItem(TOKEN_KEY);
  setToken(null);
  app.role = null;
  if (app.link) app.link.stop();
  app.link = null;
  renderConn('signedout');
  renderRole();
  showSignIn();
}

function startLink() {
  if (app.link) app.link.stop();
  app.link = new Link({
    state: (s) => { renderConn(s); app.emit('conn', s); },
    telemetry: (t) => app.emit('telemetry', t),
    status: (st) => app.setStatus(st),
    sweep: (s) => {
      if (app.status && s.id != null) { app.status.sweep = { ...(app.status.sweep || {}), ...s }; renderBenchPills(app.status); }
      app.emit('sweep-progress', s);
    },
    event: (e) => app.emit('event', e),
    hello: (h) => { if (h.role && h.role !== app.role) { app.role = h.role; renderRole(); } if (h.id) app.callerId = h.id; app.noteInstance(h.instance); },
    unauthorized: () => showSignIn('The daemon no longer accepts this token.'),
    restored: () => { noteHealth(); whoami().then((me) => { app.role = me.role; app.callerId = me.id; renderRole(); }).catch(() => {}); app.refreshAll(); app.toast('Reconnected to the daemon'); },
  });
  app.link.start();
}

// The daemon's instance id: a restart is noticed on the first answer of the new daemon.
function noteHealth() {
  api('GET', '/api/health', undefined, { quiet401: true, timeoutMs: 3000 }).then((h) => app.noteInstance(h?.instance)).catch(() => {});
}

// The socket pushes a state message only when enabled/phase/trip change: setpoints, the sweep
// and events are refreshed from GET /api/bench/status once a second (the REST fallback polls
// faster by itself).
setInterval(() => {
  if (app.link && app.link.state === 'connected') api('GET', '/api/bench/status', undefined, { quiet401: true }).then((st) => app.setStatus(st)).catch(() => {});
}, 1000);

// ---- routing and shortcuts --------------------------------------------------------------------
// A view is told it is shown ('view', which makes it read its data) only once a sign-in has set
// the token: routed before, it would ask the daemon without one, and the 401 would open the
// sign-in dialog over a page about to sign in with its saved token (a reload, a link in a new
// tab). signIn() routes again when it is done.
const VIEWS = ['live', 'sweep', 'results', 'history'];
function route() {
  const m = /^#\/(\w+)(?:\/(\d+))?/.exec(location.hash);
  const view = m && VIEWS.includes(m[1]) ? m[1] : 'live';
  app.view = view;
  for (const s of document.querySelectorAll('.view')) s.hidden = s.dataset.view !== view;
  for (const a of document.querySelectorAll('[data-nav]')) {
    if (a.dataset.nav === view) a.setAttribute('aria-current', 'page'); else a.removeAttribute('aria-current');
  }
  if (app.role) app.emit('view', { view, arg: m?.[2] ? Number(m[2]) : null });
}

// An E-stop the daemon did not confirm within this: the page says so loudly, at once.
const ESTOP_TIMEOUT_MS = 1500;

async function estop() {
  if (!app.role) { app.toast('E-stop needs a sign-in', true); return; }
  $('#estop').classList.add('pressed');
  // REST and the socket at once: the first to arrive stops the bench, the second is a no-op.
  const rest = api('POST', '/api/bench/estop', {}, { timeoutMs: ESTOP_TIMEOUT_MS }).then((st) => { app.setStatus(st); return st; });
  const viaWs = app.link && app.link.state === 'connected' ? app.link.request('POST', '/api/bench/estop', {}) : Promise.reject(new Error('no socket'));
  let timer;
  const late = new Promise((_, reject) => { timer = setTimeout(() => reject(new Error('no answer')), ESTOP_TIMEOUT_MS); });
  try {
    const st = await Promise.race([Promise.any([rest, viaWs]), late]);
    if (st?.supervisor) app.setStatus(st);
    $('#estop-failed').hidden = true;
    app.toast('E-STOP: both drives disabled (reset to clear)');
  } catch (e) {
    const why = e.errors?.[0]?.message || e.message;
    // Not a toast: it stays until a status read shows the bench stopped, or it is dismissed.
    $('#estop-failed-why').textContent = why ? `(${why})` : '';
    $('#estop-failed').hidden = false;
  } finally {
    clearTimeout(timer);
  }
}

function openHelp() {
  if (!$('#help').open) $('#help').showModal();
}

// An edit field's value when it took the focus: what Esc in the field puts back.
const isField = (t) => !!t && (t.isContentEditable || ['INPUT', 'SELECT', 'TEXTAREA'].includes(t.tagName))
  && !['checkbox', 'radio', 'button', 'submit'].includes(t.type);
document.addEventListener('focusin', (e) => { if (isField(e.target) && !e.target.isContentEditable) e.target.dataset.escValue = e.target.value; });
// Within this of an Esc that restored a field, a second Esc is the E-stop.
const ESC_TWICE_MS = 1000;
let fieldEscAt = -Infinity;

document.addEventListener('keydown', (e) => {
  if (e.key === 'Escape') {
    // Esc is the E-stop; in an edit field the first Esc puts back the value the field had (what
    // Esc does in every form) and a second within a second E-stops. In the help dialog it closes
    // the dialog (what Esc does in every dialog; the dialog's own E-STOP button is there), and in
    // the sign-in dialog it does nothing (no token to stop with yet).
    e.preventDefault();
    if ($('#signin').open) return;
    if ($('#help').open) { $('#help').close(); return; }
    const t = e.target;
    if (isField(t) && !t.isContentEditable && performance.now() - fieldEscAt > ESC_TWICE_MS) {
      fieldEscAt = performance.now();
      if (t.dataset.escValue !== undefined && t.value !== t.dataset.escValue) {
        t.value = t.dataset.escValue;
        t.dispatchEvent(new Event('input', { bubbles: true }));
        t.dispatchEvent(new Event('change', { bubbles: true }));
      }
      app.toast('Edit undone. Esc again within a second: E-STOP');
      return;
    }
    fieldEscAt = -Infinity;
    estop();
    return;
  }
  const t = e.target;
  const typing = t && (t.isContentEditable || ['INPUT', 'SELECT', 'TEXTAREA'].includes(t.tagName));
  if (typing || e.ctrlKey || e.metaKey || e.altKey || document.querySelector('dialog[open]')) return;
  if (/^[1-4]$/.test(e.key)) { location.hash = `#/${VIEWS[Number(e.key) - 1]}`; e.preventDefault(); }
  else if (e.key === '?') { openHelp(); e.preventDefault(); }
});

// ---- start ------------------------------------------------------------------------------------
function init() {
  renderConn('signedout');
  renderRole();
  for (const b of document.querySelectorAll('.estop')) b.addEventListener('click', estop);
  $('#estop-failed-dismiss').addEventListener('click', () => { $('#estop-failed').hidden = true; });
  $('#help-open').addEventListener('click', openHelp);
  $('#signout').addEventListener('click', signOut);
  $('#help').addEventListener('cancel', (e) => e.preventDefault());
  $('#signin').addEventListener('cancel', (e) => e.preventDefault());
  $('#signin-form').addEventListener('submit', async (e) => {
    e.preventDefault();
    const token = $('#signin-token').value.trim();
    $('#signin-submit').disabled = true;
    try {
      await signIn(token, $('#signin-remember').checked);
      $('#signin').close();
      $('#signin-token').value = '';
      app.toast(`Signed in as ${app.role}`);
    } catch (err) {
      $('#signin-error').textContent = err instanceof ApiError && err.status === 401 ? 'Unknown token.' : `Cannot sign in: ${err.message}`;
      if (err.status === 0) renderConn('offline'); // a sign-in was tried: now "unreachable" is news
    } finally {
      $('#signin-submit').disabled = false;
    }
  });
  setUnauthorizedHandler(() => showSignIn('The daemon refused the token; sign in again.'));

  new LiveView(app);
  new SweepView(app);
  new ResultsView(app);
  new HistoryView(app);
  window.addEventListener('hashchange', route);
  route();

  const saved = storedToken();
  if (saved) {
    signIn(saved).catch((e) => {
      if (e.status === 401) showSignIn('The saved token is no longer valid.');
      else { setToken(saved); app.role = null; renderRole(); startLink(); retrySignIn(saved); }
    });
  } else {
    showSignIn();
  }
}

// Daemon down at page load: keep trying to identify the saved token.
function retrySignIn(token) {
  setTimeout(() => signIn(token).catch((e) => { if (e.status === 401) showSignIn('The saved token is no longer valid.'); else retrySignIn(token); }), 2000);
}

init();
