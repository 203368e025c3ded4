// Sweep view: the builder (presets, dimensions, mode, configurations, measurement, estimate, the
// plan checked against the bench's limits) and the progress of the current sweep (per-point
// status cells, keyboard-reachable; ETA; abort with a reason; efficiency map and trajectories
// filling in as points complete).
import { api, ApiError, getToken } from '../api.js';
import { tripReason } from '../trip.js';
import { ChartCard } from '../charts.js';
import { ESTIMATORS, benchLimitErrors, describePlan, expandGroups, expandPlan, fmtDuration, values } from '../plan.js';
import { effMapOption, trajectoriesOption, cfgLabel } from './plots.js';
import { escapeHtml } from './live.js';
import { ProgressCells } from './sweep_cells.js';

const $ = (s) => document.querySelector(s);
const ACTIVE = ['running', 'pausing', 'paused', 'stopping'];

// Presets the page knows when the daemon has no GET /api/presets.
const BUILTIN_PRESETS = [
  { name: 'thesis-grid',
    plan: { preset: 'thesis-grid', dimensions: { speed_rpm: { from: 100, to: 900, step: 200 }, load_Nm: { from: 0.5, to: 3.5, step: 0.5 }, angle_deg: { from: 40, to: 76, step: 2 },
      configurations: [{ estimator: 'encoder', pwm: 'capwm' }, { estimator: 'encoder', pwm: 'aspwm' }, { estimator: 'ekf-basic', pwm: 'aspwm' }, { estimator: 'ekf-rs', pwm: 'aspwm' },
        { estimator: 'hfi', pwm: 'capwm' }, { estimator: 'eemf-const', pwm: 'capwm', min_speed_rpm: 500 }, { estimator: 'eemf-lut', pwm: 'capwm', min_speed_rpm: 500 }, { estimator: 'eemf-rls', pwm: 'capwm', min_speed_rpm: 500 }] } } },
  { name: 'iec-61800-9-2',
    plan: { preset: 'iec-61800-9-2', dimensions: { operating_points: [[100, 0.875], [100, 1.75], [100, 3.5], [750, 0.875], [750, 1.75], [750, 3.5], [1350, 1.75], [1350, 3.5]].map(([s, l]) => ({ speed_rpm: s, load_Nm: l })),
      angle_deg: { from: 40, to: 76, step: 2 }, configurations: [{ estimator: 'encoder', pwm: 'capwm' }] } } },
];
const QUICK = { name: 'quick-twin-check',
  plan: { name: 'quick twin check', dimensions: { speed_rpm: [300, 600], load_Nm: [1, 2], angle_deg: { from: 44, to: 64, step: 10 }, configurations: [{ estimator: 'encoder', pwm: 'capwm' }] },
    window_s: 0.2, gate: { span_s: 0.2, min_settle_s: 0.2, timeout_s: 3 }, thermal: { enabled: false } } };

// A list that is an even range of >= 3 values becomes {from, to, step}.
function asRange(list) {
  if (!Array.isArray(list)) return list;
  if (list.length < 3) return list;
  const step = Math.round((list[1] - list[0]) * 1e9) / 1e9;
  if (!(step > 0)) return list;
  for (let i = 2; i < list.length; i++) if (Math.abs(list[i] - list[i - 1] - step) > 1e-9) return list;
  return { from: list[0], to: list[list.length - 1], step };
}

export class SweepView {
  constructor(app) {
    this.app = app;
    this.presets = [];
    this.base = {};
    this.current = null;       // {id, meta, plan, points, analysis, expanded}
    this.buildDims();
    this.cells = new ProgressCells($('#p-cells'), $('#p-cell-detail'));
    this.mapCard = new ChartCard($('[data-chart="p-map"]'), { title: 'Efficiency map (ME angle)' });
    this.trajCard = new ChartCard($('[data-chart="p-traj"]'), { title: 'MTPA / ME trajectories' });
    this.loadPresets(false);

    const form = $('#builder');
    form.addEventListener('input', (e) => { if (e.target.id !== 'b-preset') this.changed(); });
    form.addEventListener('change', (e) => { if (e.target.id !== 'b-preset') this.changed(); });
    $('#b-preset').addEventListener('change', () => this.applyPreset($('#b-preset').value));
    $('#b-add-config').addEventListener('click', () => { this.addConfig({ estimator: 'encoder', pwm: 'capwm' }); this.changed(); });
    form.addEventListener('submit', (e) => { e.preventDefault(); this.create(true); });
    $('#b-create').addEventListener('click', () => this.create(false));
    for (const a of ['pause', 'resume']) $(`#p-${a}`).addEventListener('click', () => this.action(a));
    $('#p-abort').addEventListener('click', () => this.askAbort());
    this.abortDialog();
    $('#p-restart').addEventListener('click', () => this.action('start'));
    $('#p-reset').addEventListener('click', () => app.command('POST', '/api/bench/reset', {}, 'Trip and faults reset').catch(() => {}));

    app.on('view', ({ view, arg }) => {
      this.visible = view === 'sweep';
      if (this.visible && arg) this.select(arg);
      if (this.visible) this.refreshCurrent(true);
    });
    app.on('status', (st) => this.onStatus(st));
    app.on('sweep-progress', (s) => this.onProgress(s));
    app.on('refresh', () => { this.refreshCurrent(true); if (!this.presetsFromDaemon) this.loadPresets(true); this.loadBenchConfig(); });
    // Signed in (or the role changed): what was refused before the token is asked again.
    app.on('role', () => { this.renderButtons(); if (app.role) this.loadBenchConfig(); this.changed(); });
    setInterval(() => { if (this.visible && this.current && ACTIVE.includes(this.current.state)) this.refreshCurrent(false); }, 2000);
  }

  // ---- builder ----------------------------------------------------------------------------------
  buildDims() {
    const fs = $('#b-dims');
    fs.insertAdjacentHTML('beforeend', `
      <label class="check"><input type="checkbox" id="b-oppoints"> Explicit operating points (speed, load pairs) instead of a grid</label>
      ${['speed_rpm:Speed:rpm', 'load_Nm:Load:N m', 'angle_deg:Angle:deg'].map((d) => {
        const [key, label, unit] = d.split(':');
        return `<div class="dimrow" data-dim="${key}">
          <span class="lbl" id="lbl-${key}">${label} <span class="unit">${unit}</span></span>
          <select aria-label="${label}: list or range" data-role="kind"><option value="range">range</option><option value="list">list</option></select>
          <div class="vals">
            <label>from<input data-role="from" type="number" step="any" aria-describedby="lbl-${key}"></label>
            <label>to<input data-role="to" type="number" step="any" aria-describedby="lbl-${key}"></label>
            <label>step<input data-role="step" type="number" step="any" aria-describedby="lbl-${key}"></label>
          </div>
          <div class="vals list" hidden><label>values<input data-role="list" type="text" inputmode="decimal" placeholder="e.g. 300, 600" title="comma-separated values" aria-describedby="lbl-${key}"></label></div>
          <p class="field-error" id="b-err-${key}" role="alert" hidden></p>
        </div>`;
      }).join('')}
      <label id="b-points-wrap" hidden>Operating points: one "speed_rpm load_Nm [label]" per line<textarea id="b-points" rows="5" spellcheck="false"></textarea></label>
      <p class="field-error" id="b-err-operating_points" role="alert" hidden></p>`);
    for (const row of fs.querySelectorAll('.dimrow')) {
      row.querySelector('[data-role="kind"]').addEventListener('change', (e) => this.setKind(row, e.target.value));
    }
    $('#b-oppoints').addEventListener('change', () => this.syncVisibility());
    for (const r of document.querySelectorAll('input[name="b-mode"]')) r.addEventListener('change', () => this.syncVisibility());
  }

  setKind(row, kind) {
    row.querySelector('[data-role="kind"]').value = kind;
    const [range, list] = row.querySelectorAll('.vals');
    range.hidden = kind !== 'range';
    list.hidden = kind !== 'list';
  }

  setDim(key, dim) {
    const row = document.querySelector(`.dimrow[data-dim="${key}"]`);
    const d = asRange(dim);
    if (d && !Array.isArray(d)) {
      this.setKind(row, 'range');
      row.querySelector('[data-role="from"]').value = d.from;
      row.querySelector('[data-role="to"]').value = d.to;
      row.querySelector('[data-role="step"]').value = d.step;
      row.querySelector('[data-role="list"]').value = values(d).join(', ');
    } else {
      this.setKind(row, 'list');
      row.querySelector('[data-role="list"]').value = (d || []).join(', ');
    }
  }

  getDim(key) {
    const row = document.querySelector(`.dimrow[data-dim="${key}"]`);
    if (row.querySelector('[data-role="kind"]').value === 'range') {
      const n = (r) => Number(row.querySelector(`[data-role="${r}"]`).value);
      return { from: n('from'), to: n('to'), step: n('step') };
    }
    return row.querySelector('[data-role="list"]').value.split(/[,;\s]+/).filter(Boolean).map(Number);
  }

  syncVisibility() {
    const adaptive = this.mode() === 'adaptive';
    const pts = $('#b-oppoints').checked;
    document.querySelector('.dimrow[data-dim="angle_deg"]').hidden = adaptive;
    document.querySelector('.dimrow[data-dim="speed_rpm"]').hidden = pts;
    document.querySelector('.dimrow[data-dim="load_Nm"]').hidden = pts;
    $('#b-points-wrap').hidden = !pts;
    $('#b-adaptive').hidden = !adaptive;
  }

  mode() { return document.querySelector('input[name="b-mode"]:checked').value; }

  addConfig(c) {
    const row = document.createElement('div');
    row.className = 'cfgrow';
    const n = $('#b-configs').children.length + 1;
    row.innerHTML = `<select aria-label="Configuration ${n}: estimator" data-role="est">${ESTIMATORS.map((e) => `<option ${e === c.estimator ? 'selected' : ''}>${e}</option>`).join('')}</select>
      <select aria-label="Configuration ${n}: PWM" data-role="pwm"><option value="capwm" ${c.pwm === 'capwm' ? 'selected' : ''}>CAPWM</option><option value="aspwm" ${c.pwm === 'aspwm' ? 'selected' : ''}>ASPWM</option></select>
      <input type="number" step="any" min="0" data-role="avg" placeholder="plan's" title="gate averaging for this configuration (s); empty: the plan's" aria-label="Configuration ${n}: gate averaging (s)">
      <button type="button" class="small" aria-label="Remove configuration ${n}">Remove</button>`;
    row.dataset.min = c.min_speed_rpm ?? '';
    row.dataset.max = c.max_speed_rpm ?? '';
    const avg = row.querySelector('[data-role="avg"]');
    avg.value = c.gate_average_s ?? '';
    row.querySelector('button').addEventListener('click', () => { row.remove(); this.changed(); });
    // A preset's speed bounds and averaging belong to its estimator (EEMF from 500 rpm, the
    // injecting estimators averaged): a new estimator starts without them.
    row.querySelector('[data-role="est"]').addEventListener('change', () => { row.dataset.min = ''; row.dataset.max = ''; avg.value = ''; });
    $('#b-configs').append(row);
  }

  async loadPresets(ask) {
    let list = null;
    if (ask) try { list = await api('GET', '/api/presets', undefined, { quiet401: true }); } catch { /* not there yet */ }
    this.presetsFromDaemon = Array.isArray(list) && list.length > 0;
    if (ask && !this.presetsFromDaemon && this.presets.length) return; // keep the form as it is
    const keep = this.presets.length ? $('#b-preset').value : null;
    this.presets = [QUICK, ...(this.presetsFromDaemon ? list : BUILTIN_PRESETS)];
    $('#b-preset').innerHTML = `<option value="">custom (start from the current form)</option>`
      + this.presets.map((p) => `<option value="${escapeHtml(p.name)}">${escapeHtml(p.name)}</option>`).join('');
    if (keep !== null) { $('#b-preset').value = keep; return; } // the user's form stays
    $('#b-preset').value = QUICK.name;
    this.applyPreset(QUICK.name);
  }

  applyPreset(name) {
    const p = this.presets.find((x) => x.name === name);
    // Derived from what the preset loads, never its hand-written text.
    $('#b-preset-desc').textContent = p ? describePlan(p.plan) : 'Edit any field below.';
    if (!p) { this.changed(); return; }
    this.fillForm(p.plan, name);
  }

  fillForm(plan, name) {
    const { preset, ...base } = plan;
    this.base = JSON.parse(JSON.stringify(base));
    const d = plan.dimensions || {};
    $('#b-name').value = plan.name || name || 'sweep';
    document.querySelector(`input[name="b-mode"][value="${plan.mode === 'adaptive' ? 'adaptive' : 'grid'}"]`).checked = true;
    $('#b-oppoints').checked = !!d.operating_points;
    if (d.operating_points) $('#b-points').value = d.operating_points.map((p) => `${p.speed_rpm} ${p.load_Nm}${p.label ? ` ${p.label}` : ''}`).join('\n');
    this.setDim('speed_rpm', d.speed_rpm || [300, 600]);
    this.setDim('load_Nm', d.load_Nm || [1, 2]);
    this.setDim('angle_deg', d.angle_deg || { from: 40, to: 76, step: 2 });
    $('#b-configs').innerHTML = '';
    for (const c of d.configurations || [{ estimator: 'encoder', pwm: 'capwm' }]) this.addConfig(c);
    const a = plan.adaptive || {};
    $('#b-br-from').value = a.bracket_deg?.[0] ?? 40;
    $('#b-br-to').value = a.bracket_deg?.[1] ?? 76;
    $('#b-tol').value = a.tolerance_deg ?? 1;
    $('#b-maxev').value = a.max_evaluations ?? 7;
    $('#b-stencil').value = a.stencil_deg ?? 6;
    $('#b-angle-u').value = a.angle_u_target_deg ?? '';
    $('#b-pdcm-u').value = plan.precision?.pdcm_u_repeat_target_W ?? '';
    $('#b-max-window').value = plan.precision?.max_window_s ?? 8;
    $('#b-window').value = plan.window_s ?? 1;
    $('#b-span').value = plan.gate?.span_s ?? 0.5;
    $('#b-settle').value = plan.gate?.min_settle_s ?? 0.5;
    $('#b-timeout').value = plan.gate?.timeout_s ?? 30;
    $('#b-average').value = plan.gate?.average_s ?? 0;
    $('#b-thermal').checked = plan.thermal?.enabled ?? true;
    this.syncVisibility();
    this.changed();
  }

  planFromForm() {
    const plan = JSON.parse(JSON.stringify(this.base || {}));
    delete plan.preset;
    plan.name = $('#b-name').value.trim() || 'sweep';
    plan.mode = this.mode();
    const dims = {};
    if ($('#b-oppoints').checked) {
      dims.operating_points = $('#b-points').value.split('\n').map((l) => l.trim()).filter(Boolean).map((l) => {
        const [s, t, ...label] = l.split(/\s+/);
        const p = { speed_rpm: Number(s), load_Nm: Number(t) };
        if (label.length) p.label = label.join(' ');
        return p;
      });
    } else {
      dims.speed_rpm = this.getDim('speed_rpm');
      dims.load_Nm = this.getDim('load_Nm');
    }
    if (plan.mode === 'grid') dims.angle_deg = this.getDim('angle_deg');
    dims.configurations = [...$('#b-configs').children].map((row) => {
      const c = { estimator: row.querySelector('[data-role="est"]').value, pwm: row.querySelector('[data-role="pwm"]').value };
      if (row.dataset.min !== '') c.min_speed_rpm = Number(row.dataset.min);
      if (row.dataset.max !== '' && row.dataset.max !== 'null') c.max_speed_rpm = Number(row.dataset.max);
      const avg = row.querySelector('[data-role="avg"]').value.trim();
      if (avg !== '') c.gate_average_s = Number(avg);
      return c;
    });
    plan.dimensions = dims;
    if (plan.mode === 'adaptive') {
      plan.adaptive = { ...(plan.adaptive || {}), bracket_deg: [Number($('#b-br-from').value), Number($('#b-br-to').value)],
        tolerance_deg: Number($('#b-tol').value), max_evaluations: Number($('#b-maxev').value), stencil_deg: Number($('#b-stencil').value) };
      const angleU = $('#b-angle-u').value.trim();
      if (angleU !== '') plan.adaptive.angle_u_target_deg = Number(angleU);
      else delete plan.adaptive.angle_u_target_deg;
    } else {
      delete plan.adaptive;
    }
    plan.window_s = Number($('#b-window').value);
    plan.gate = { ...(plan.gate || {}), span_s: Number($('#b-span').value), min_settle_s: Number($('#b-settle').value), timeout_s: Number($('#b-timeout').value),
      average_s: Number($('#b-average').value) };
    plan.thermal = { ...(plan.thermal || {}), enabled: $('#b-thermal').checked };
    // Measure until sure (docs/sweep-plan.md, "precision"): only when a target is given.
    const pdcmU = $('#b-pdcm-u').value.trim();
    if (pdcmU !== '') plan.precision = { mode: 'lengthen', pdcm_u_repeat_target_W: Number(pdcmU), max_window_s: Number($('#b-max-window').value) };
    else delete plan.precision;
    return plan;
  }

  changed() {
    const plan = this.planFromForm();
    $('#b-json').textContent = JSON.stringify(plan, null, 2);
    this.showPlanErrors(benchLimitErrors(plan, this.benchConfig));
    clearTimeout(this.estTimer);
    this.estTimer = setTimeout(() => this.estimate(plan), 250);
  }

  async loadBenchConfig() {
    try { this.benchConfig = await api('GET', '/api/bench/config', undefined, { quiet401: true }); } catch { return; }
    this.showPlanErrors(benchLimitErrors(this.planFromForm(), this.benchConfig));
  }

  // Problems at their JSON pointers ({pointer, message}) shown at the field they name; any
  // problem disables Create.
  showPlanErrors(errors) {
    const byField = new Map();
    for (const e of errors) {
      const key = /^\/dimensions\/(speed_rpm|load_Nm|angle_deg|operating_points)/.exec(e.pointer)?.[1];
      if (!key) continue;
      byField.set(key, [...(byField.get(key) || []), e.message]);
    }
    for (const key of ['speed_rpm', 'load_Nm', 'angle_deg', 'operating_points']) {
      const el = $(`#b-err-${key}`);
      const msgs = byField.get(key);
      el.hidden = !msgs;
      el.textContent = msgs ? msgs.join('; ') : '';
      const inputs = key === 'operating_points' ? [$('#b-points')] : document.querySelectorAll(`.dimrow[data-dim="${key}"] input`);
      for (const i of inputs) { if (msgs) { i.setAttribute('aria-invalid', 'true'); i.setAttribute('aria-errormessage', el.id); } else i.removeAttribute('aria-invalid'); }
    }
    this.planErrors = errors;
    this.renderButtons();
  }

  async estimate(plan) {
    const el = $('#b-estimate');
    const seq = (this.estSeq = (this.estSeq || 0) + 1);
    let text, bad = false, errors = benchLimitErrors(plan, this.benchConfig);
    if (!getToken()) {
      // Nothing is sent before a sign-in; signing in asks again (the 'role' event).
      el.textContent = 'sign in to estimate: no plan is sent to the daemon without a token';
      el.classList.remove('bad');
      el.dataset.points = '';
      this.showPlanErrors(errors);
      return;
    }
    try {
      const r = await api('POST', '/api/sweeps/estimate', plan, { quiet401: true });
      text = `${r.points}${r.upper_bound || plan.mode === 'adaptive' ? ' points at most' : ' points'}, about ${fmtDuration(r.duration_s)} of bench time`;
      this.lastEstimate = r;
    } catch (e) {
      bad = true;
      const planProblem = e instanceof ApiError && (e.code === 'bad_plan' || e.status === 400);
      text = planProblem ? `Plan problems: ${e.message}` : `cannot estimate: ${e.message}`;
      // "/dimensions/speed_rpm: 1600 rpm exceeds ...; /gate/span_s: ..." -> at their fields
      if (planProblem) {
        errors = e.message.split('; ').map((m) => /^(\/[^:]*): (.*)$/.exec(m)).filter(Boolean).map(([, pointer, message]) => ({ pointer, message }));
      }
    }
    if (seq !== this.estSeq) return;
    this.showPlanErrors(errors);
    el.textContent = text;
    el.classList.toggle('bad', bad);
    el.dataset.points = bad ? '' : String(this.lastEstimate?.points ?? '');
  }

  async create(start) {
    const plan = this.planFromForm();
    if (this.planErrors?.length) return;
    let s;
    try {
      s = await this.app.command('POST', '/api/sweeps', plan, start ? null : 'Sweep created');
    } catch { return; }
    this.app.refreshSweeps();
    this.select(s.id, s);
    if (start) await this.action('start');
  }

  // ---- progress --------------------------------------------------------------------------------
  // Abort asks first: Enter confirms (the reason field or the button), Esc or Cancel keeps the
  // sweep running. Esc inside this dialog closes it and is no E-stop (its keydown stops here).
  abortDialog() {
    const dlg = $('#abort-dialog');
    dlg.addEventListener('keydown', (e) => {
      if (e.key !== 'Escape') return;
      e.stopPropagation();
      e.preventDefault();
      dlg.close('cancel');
    });
    dlg.addEventListener('cancel', (e) => { e.preventDefault(); dlg.close('cancel'); });
    $('#abort-cancel').addEventListener('click', () => dlg.close('cancel'));
    $('#abort-form').addEventListener('submit', (e) => {
      e.preventDefault();
      dlg.close('confirm');
    });
    dlg.addEventListener('close', () => {
      if (dlg.returnValue === 'confirm') this.action('abort', { reason: $('#abort-reason').value.trim() });
      $('#p-abort').focus();
    });
  }

  askAbort() {
    if (!this.current) return;
    const dlg = $('#abort-dialog');
    $('#abort-title').textContent = `Abort sweep #${this.current.id}?`;
    $('#abort-reason').value = '';
    dlg.returnValue = '';
    dlg.showModal();
    $('#abort-reason').focus();
  }

  async action(a, body = {}) {
    if (!this.current) return;
    try {
      await this.app.command('POST', `/api/sweeps/${this.current.id}/${a}`, body, `Sweep ${this.current.id}: ${a}`);
      this.followRunning = true;
    } catch { /* toast shown */ }
    this.refreshCurrent(true);
    this.app.refreshSweeps();
  }

  select(id, meta) {
    if (this.current?.id !== id) {
      this.current = { id, meta: meta || null, points: [], analysis: null, state: meta?.state };
      this.lastDone = -1;
    }
    this.refreshCurrent(true);
  }

  onStatus(st) {
    this.renderButtons(); // a trip latched or reset changes what may start
    const s = st.sweep;
    if (!s) return;
    // Follow the running sweep (started here, from another page or a CLI).
    if (ACTIVE.includes(s.state) && this.current?.id !== s.id) this.select(s.id);
    if (!this.current && s.id) this.select(s.id);
    if (this.current?.id === s.id) this.onProgress(s);
  }

  onProgress(s) {
    if (!this.current || this.current.id !== s.id) { if (s.id && ACTIVE.includes(s.state)) this.select(s.id); return; }
    const c = this.current;
    if (c.state !== s.state) this.app.refreshSweeps();
    c.state = s.state;
    c.done = s.done;
    c.total = s.total;
    if (s.eta_s !== undefined) c.eta_s = s.eta_s;
    if (s.error) c.error = s.error;
    if (s.done !== this.lastDone) {
      this.lastDone = s.done;
      this.loadData();
    }
    this.renderProgress();
  }

  async refreshCurrent(full) {
    if (!this.current) {
      // Nothing chosen: the most recent sweep of the history.
      const last = this.app.sweeps?.[this.app.sweeps.length - 1];
      if (last) this.select(last.id, last); else this.renderProgress();
      return;
    }
    const id = this.current.id;
    try {
      const meta = await api('GET', `/api/sweeps/${id}`);
      if (this.current?.id !== id) return;
      this.current.meta = meta;
      this.current.plan = meta.plan;
      if (!this.current.expanded) this.current.expanded = expandPlan(meta.plan);
      const run = this.app.status?.sweep;
      if (!(run && run.id === id)) {
        this.current.state = meta.state;
        this.current.done = meta.points_stored;
        this.current.total = meta.total_points;
        this.current.error = meta.last_error;
      } else if (this.current.done == null) {
        this.onProgress(run);
      }
      if (full || this.current.done !== this.lastLoadedDone) await this.loadData();
    } catch (e) { if (e.status === 404) this.current = null; }
    this.renderProgress();
  }

  async loadData() {
    if (!this.current || this.loading) { this.reload = true; return; }
    this.loading = true;
    const c = this.current;
    try {
      const points = await api('GET', `/api/sweeps/${c.id}/points`);
      c.points = points;
      this.lastLoadedDone = c.done;
      // The daemon's analysis (docs/analysis.md): one implementation, the one the reports use.
      try { c.analysis = await api('GET', `/api/sweeps/${c.id}/analysis`, undefined, { quiet401: true }); } catch (e) {
        c.analysis = null;
        console.warn('analysis', e.message);
      }
      this.renderProgress();
      this.renderCharts();
    } catch (e) {
      console.warn('points', e.message);
    } finally {
      this.loading = false;
      if (this.reload) { this.reload = false; setTimeout(() => this.loadData(), 300); }
    }
  }

  // The daemon's figure (bench/pace.hpp: bench time per point so far); null until it has one.
  eta() {
    return this.current.eta_s ?? null;
  }

  renderButtons() {
    const c = this.current;
    const op = this.app.isOperator;
    const st = c?.state;
    $('#p-pause').disabled = !op || !c || st !== 'running';
    $('#p-resume').disabled = !op || !c || st !== 'paused';
    $('#p-abort').disabled = !op || !c || !ACTIVE.includes(st);
    // A latched trip: nothing starts the bench until Reset trip (trip.js says why, in words).
    const tripped = tripReason(this.app.status);
    $('#p-restart').disabled = !op || !c || ACTIVE.includes(st) || st === 'completed' || !!tripped;
    $('#p-restart').title = tripped && c && !ACTIVE.includes(st) && st !== 'completed' ? tripped : '';
    const bad = !!this.planErrors?.length;
    $('#b-start').disabled = !op || bad || !!tripped;
    $('#b-start').title = tripped;
    $('#p-reset').disabled = !op;
    $('#b-create').disabled = !op || bad;
  }

  renderProgress() {
    const c = this.current;
    this.renderButtons();
    if (!c) { $('#p-line').textContent = 'No sweep yet: build one on the left.'; return; }
    const total = c.total ?? c.meta?.total_points ?? 0;
    const done = c.done ?? c.meta?.points_stored ?? 0;
    const pct = total ? Math.min(100, Math.floor((100 * done) / total)) : 0;
    const shownPct = c.state === 'completed' ? 100 : pct;
    $('#p-title').textContent = `#${c.id} ${c.meta?.name || ''}`;
    $('#p-bar span').style.width = `${shownPct}%`;
    $('#p-bar').setAttribute('aria-valuenow', String(shownPct));
    $('#p-pct').textContent = `${shownPct} %`;
    $('#p-pct').dataset.pct = String(shownPct);
    const eta = this.eta();
    const parts = [`<span class="state ${c.state}" id="p-state">${c.state || '?'}</span>`, `${done} / ${total} points`];
    // Paused, the time left does not run down: no counting ETA until it resumes.
    if (c.state === 'paused') parts.push('<span id="p-eta">paused</span>');
    else if (ACTIVE.includes(c.state)) parts.push(`<span id="p-eta">ETA ${eta == null ? 'estimating…' : fmtDuration(eta)}</span>`);
    if (c.meta?.plan?.mode === 'adaptive') parts.push('adaptive: total is an upper bound');
    if (c.error) parts.push(`<span class="error" id="p-error">${c.state === 'aborted' ? 'reason: ' : ''}${escapeHtml(c.error)}</span>`);
    $('#p-line').innerHTML = parts.join(' · ');
    this.renderCells(total);
  }

  renderCells(total) {
    const c = this.current;
    const adaptive = c.meta?.plan?.mode === 'adaptive';
    if (adaptive && !c.groups) c.groups = expandGroups(c.meta.plan);
    this.cells.render({ id: c.id, state: c.state, error: c.error, points: c.points || [], total, expanded: c.expanded,
      groups: adaptive ? c.groups : null, maxEvaluations: c.meta?.plan?.adaptive?.max_evaluations ?? 7 });
  }

  renderCharts() {
    const a = this.current?.analysis;
    const cfg = a?.efficiency_map?.entries?.[0] || a?.curves?.entries?.[0];
    this.mapCard.set(effMapOption(a, cfg), { empty: 'fills in as curves complete' });
    this.trajCard.set(trajectoriesOption(a, cfg), { empty: 'fills in as curves complete' });
    if (cfg) {
      this.mapCard.h.textContent = `Efficiency map, ${cfgLabel(cfg)}`;
      this.trajCard.h.textContent = `MTPA / ME trajectories, ${cfgLabel(cfg)}`;
    }
  }
}
