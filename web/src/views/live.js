// Live view: time-series charts of the telemetry (last 60 s of bench time), the readout, bench
// control (setpoints, enable / ordered stop, reset, estimator and PWM, control lock) and events.
import { ChartCard, axis } from '../charts.js';
import { api } from '../api.js';
import { faultText } from '../link.js';
import { ESTIMATORS } from '../plan.js';

const WINDOW_S = 60;
const KEEP_S = 120;
const $ = (s) => document.querySelector(s);
const fmt = (v, d = 1) => (v == null || !Number.isFinite(v) ? '–' : (Math.abs(v) < 0.5 * 10 ** -d ? 0 : v).toFixed(d));

const CHARTS = [
  { id: 'speed', title: 'Speed', unit: 'rpm', series: [['speed_rpm', 'measured'], ['sp_speed', 'setpoint', true]], d: 0, span: 100 },
  { id: 'torque', title: 'Load torque', unit: 'N m', series: [['torque_Nm', 'T_L'], ['sp_load', 'setpoint', true]], d: 2, span: 0.5 },
  { id: 'currents', title: 'Currents', unit: 'A', series: [['im_A', 'I_m'], ['id_A', 'i_d'], ['iq_A', 'i_q']], d: 2, span: 0.5 },
  { id: 'udc', title: 'DC bus U_dc', unit: 'V', series: [['udc_V', 'U_dc']], d: 1, span: 10 },
  { id: 'pdc', title: 'P_dcM', unit: 'W', series: [['pdc_W', 'P_dcM']], d: 1, span: 20 },  // falls back to the drive's P_ac estimate
  { id: 'temp', title: 'Winding temperature', unit: '°C', series: [['temp_C', 'temperature']], d: 1, span: 2 },
  { id: 'poserr', title: 'Position error', unit: 'deg', series: [['pos_err_deg', 'θ̂ − θ']], d: 2, span: 1, empty: 'no live position error (the encoder is the source, or the daemon does not send it)' },
];

export class LiveView {
  constructor(app) {
    this.app = app;
    this.buf = [];          // telemetry samples
    this.cards = new Map();
    this.dirty = false;
    this.lastT = -Infinity;
    const host = $('#live-charts');
    for (const c of CHARTS) {
      const div = document.createElement('div');
      div.className = 'chart-card';
      div.dataset.chart = `live-${c.id}`;
      host.append(div);
      this.cards.set(c.id, new ChartCard(div, { title: `${c.title} [${c.unit}]` }));
    }
    this.fillEstimators(false);
    app.on('telemetry', (t) => this.onTelemetry(t));
    app.on('status', (st) => this.onStatus(st));
    app.on('event', (e) => this.addEvents([e]));
    // A new daemon instance: the old one's events are not this one's (one line says why they went).
    app.on('daemon-restarted', () => { this.events = []; this.restartNote = true; this.renderEvents(); });
    app.on('view', ({ view }) => { this.visible = view === 'live'; if (this.visible) this.dirty = true; });
    app.on('refresh', () => { this.refreshLock(); if (!this.estimatorsFromDaemon) this.fillEstimators(true); });
    setInterval(() => this.render(), 200);
    setInterval(() => { if (this.visible && app.role) this.refreshLock(); }, 5000);

    $('#setpoints-form').addEventListener('submit', (e) => {
      e.preventDefault();
      const f = e.target;
      const body = {};
      for (const k of ['speed_rpm', 'load_Nm', 'angle_deg']) if (f[k].value !== '') body[k] = Number(f[k].value);
      app.command('POST', '/api/bench/setpoints', body, 'Setpoints applied').catch(() => {});
      this.spEdited = false;
    });
    $('#setpoints-form').addEventListener('input', () => { this.spEdited = true; });
    $('#btn-enable').addEventListener('click', () => app.command('POST', '/api/bench/enable', { enabled: true }, 'Bench enabled').catch(() => {}));
    $('#btn-disable').addEventListener('click', () => app.command('POST', '/api/bench/enable', { enabled: false }, 'Ordered stop').catch(() => {}));
    $('#btn-reset').addEventListener('click', () => app.command('POST', '/api/bench/reset', {}, 'Trip and faults reset').catch(() => {}));
    $('#btn-lock').addEventListener('click', () => app.command('POST', '/api/bench/lock', {}, 'Control lock taken').then(() => this.refreshLock()).catch(() => {}));
    $('#btn-unlock').addEventListener('click', () => app.command('DELETE', '/api/bench/lock', undefined, 'Control lock released').then(() => this.refreshLock()).catch(() => {}));
    $('#mode-form').addEventListener('submit', (e) => {
      e.preventDefault();
      const f = e.target;
      const body = { estimator: f.estimator.value, pwm: f.pwm.value };
      // POST /api/bench/mode (the daemon's name for it); /api/bench/estimator as first announced
      app.link.request('POST', '/api/bench/mode', body)
        .catch((e) => { if (e.status === 404) return app.link.request('POST', '/api/bench/estimator', body); throw e; })
        .then((st) => { if (st?.supervisor) app.setStatus(st); app.toast('Estimator and PWM set'); })
        .catch((e) => app.toast(`mode: ${e.message}${e.code ? ` (${e.code})` : ''}`, true));
    });
  }

  async fillEstimators(ask) {
    let names = ESTIMATORS;
    if (ask) {
      try {
        const list = await api('GET', '/api/estimators', undefined, { quiet401: true });
        if (Array.isArray(list) && list.length) { names = list.map((e) => e.name || e); this.estimatorsFromDaemon = true; }
      } catch { /* route not there yet: the fixed list */ }
    }
    const sel = $('#live-estimator');
    const prev = sel.value;
    sel.innerHTML = names.map((n) => `<option value="${n}">${n}</option>`).join('');
    if (names.includes(prev)) sel.value = prev;
  }

  onTelemetry(t) {
    if (t.t_s == null || t.t_s <= this.lastT) {
      if (t.t_s != null && t.t_s < this.lastT - 1) { this.buf = []; this.events = []; } // bench clock restarted (daemon restart)
      else return;
    }
    this.lastT = t.t_s;
    const sp = this.app.status?.setpoints || {};
    // Live P_dcM when the daemon sends it; else the drive's own output-power estimate P_ac
    // (the VFC meter measures P_dcM only over a point's window).
    const pdcLive = t.pdc_W != null;
    if (pdcLive !== this.pdcLive) {
      this.pdcLive = pdcLive;
      const h = this.cards.get('pdc').h;
      h.textContent = pdcLive ? 'P_dcM [W]' : 'Drive power P_ac [W]';
      h.title = pdcLive ? 'DC power into the SynRM drive' : 'The drive\'s own output-power estimate: the daemon sends no live P_dcM (the VFC meter measures it over each point\'s window)';
    }
    const sample = { ...t, pdc_W: t.pdc_W ?? t.pac_W ?? null, sp_speed: sp.speed_rpm, sp_load: sp.load_Nm };
    this.buf.push(sample);
    const cut = t.t_s - KEEP_S;
    if (this.buf.length > 50 && this.buf[0].t_s < cut) this.buf = this.buf.filter((s) => s.t_s >= cut);
    this.latest = sample;
    this.dirty = true;
  }

  render() {
    if (!this.visible || !this.dirty) return;
    this.dirty = false;
    this.renderReadout();
    // A strip chart: 0..60 s for the first minute, then the last 60 s.
    const t1 = Math.max(this.lastT, WINDOW_S);
    const t0 = t1 - WINDOW_S;
    const rows = this.buf.filter((s) => s.t_s >= t0);
    for (const c of CHARTS) {
      const card = this.cards.get(c.id);
      const series = c.series.map(([key, name, dashed]) => ({
        name, type: 'line', showSymbol: false, sampling: 'lttb', connectNulls: false,
        lineStyle: { width: dashed ? 1.5 : 2, type: dashed ? 'dashed' : 'solid' },
        data: rows.map((s) => [s.t_s, s[key] ?? null]),
      }));
      if (!card.chart) {
        card.set({
          legend: c.series.length > 1 ? { top: 0, right: 70, textStyle: { color: '#14181f' } } : undefined,
          grid: { left: 52, right: 12, top: 26, bottom: 26 },
          xAxis: axis('', { min: t0, max: t1, splitNumber: 4, axisLabel: { color: '#333b47', formatter: clock } }),
          // at least `span` of range, so noise around a constant does not fill the chart
          yAxis: axis('', { min: (v) => niceLo(v, c.span), max: (v) => niceHi(v, c.span) }),
          series,
        }, { empty: c.empty || 'waiting for telemetry' });
      } else {
        card.update({ xAxis: { min: t0, max: t1 }, series: series.map((s) => ({ data: s.data })) });
      }
      const v = this.latest?.[c.series[0][0]];
      card.value(v == null ? '–' : `${fmt(v, c.d)} ${c.unit}`);
    }
  }

  onStatus(st) {
    this.status = st;
    this.renderReadout();
    const f = $('#setpoints-form');
    // A new trip zeroed the daemon's setpoints: the form shows that, whatever was being typed
    // (judged on full statuses only: the socket's state pushes carry no setpoints).
    const newTrip = !!st.setpoints && !!st.supervisor?.trip && !this.tripSeen;
    if (st.setpoints) this.tripSeen = !!st.supervisor?.trip;
    if (newTrip) this.spEdited = false;
    if (st.setpoints && (newTrip || (!this.spEdited && !f.contains(document.activeElement)))) {
      f.speed_rpm.value = st.setpoints.speed_rpm;
      f.load_Nm.value = st.setpoints.load_Nm;
      f.angle_deg.value = st.setpoints.angle_deg;
    }
    const m = $('#mode-form');
    if (st.mode && !m.contains(document.activeElement) && !this.modeShown) {
      m.estimator.value = st.mode.estimator;
      m.pwm.value = st.mode.pwm;
      this.modeShown = true; // once: later the operator's choice stays in the form
    }
    if (Array.isArray(st.events)) this.setEvents(st.events);
  }

  // Measured values from the latest telemetry (20 Hz), the rest from the status.
  renderReadout() {
    const st = this.status || {};
    const s = st.synrm || {};
    const t = this.latest && this.latest.t_s >= (st.t_s ?? 0) - 2 ? this.latest : null;
    const v = (k, sk = k) => (t && t[k] != null ? t[k] : s[sk]);
    const rows = [
      ['state', (t ? t.enabled : st.enabled) ? 'enabled' : 'disabled'],
      ['phase', (t && t.phase) || st.supervisor?.phase || '–'],
      ['speed', `${fmt(v('speed_rpm'), 0)} rpm`],
      ['I_m', `${fmt(v('im_A'), 2)} A`],
      ['load', `${fmt(t?.torque_Nm ?? st.load?.torque_Nm, 2)} N m`],
      ['U_dc', `${fmt(v('udc_V'), 1)} V`],
      ['temperature', `${fmt(v('temp_C'), 1)} °C`],
      ['setpoints', `${fmt(st.setpoints?.speed_rpm, 0)} rpm, ${fmt(st.setpoints?.load_Nm, 2)} N m, ${fmt(st.setpoints?.angle_deg, 1)}°`],
    ];
    if (st.mode || st.estimator) rows.push(['estimator', `${st.mode?.estimator || st.estimator} / ${st.mode?.pwm || st.pwm || ''}`]);
    if (st.supervisor?.trip) rows.push(['trip', `${faultText(st.supervisor.trip.fault, st.supervisor.trip.fault_code_raw)}: ${st.supervisor.trip.detail}`]);
    if (st.supervisor?.alarm) rows.push(['ALARM', st.supervisor.alarm.detail]);
    if (st.heartbeats === false) rows.push(['heartbeats', "stopped until reset: the drives' watchdogs are armed"]);
    const html = rows.map(([k, val]) => `<dt>${k}</dt><dd data-k="${k}">${escapeHtml(String(val))}</dd>`).join('');
    if (html !== this.readoutHtml) { this.readoutHtml = html; $('#readout').innerHTML = html; }
  }

  // Events from the status (the most recent 50) and pushed over the socket, each once.
  setEvents(events) { this.addEvents(events); }

  addEvents(evs) {
    const all = new Map((this.events || []).map((e) => [eventKey(e), e]));
    let changed = false;
    for (const e of evs) if (!all.has(eventKey(e))) { all.set(eventKey(e), e); changed = true; }
    if (!changed && this.events) return;
    this.events = [...all.values()].sort((a, b) => a.t_s - b.t_s).slice(-50);
    this.renderEvents();
  }

  renderEvents() {
    $('#events').innerHTML = this.events.slice().reverse()
      .map((e) => `<li><b>${fmt(e.t_s, 1)} s ${escapeHtml(e.kind)}</b>${escapeHtml(e.message)}</li>`).join('')
      + (this.restartNote ? '<li class="restart-note"><b>link</b>daemon restarted</li>' : '');
  }

  async refreshLock() {
    try {
      const l = await api('GET', '/api/bench/lock', undefined, { quiet401: true });
      $('#lock-line').textContent = l.holder ? `Control lock: ${l.holder}${l.expires_in_s != null ? ` (expires in ${Math.round(l.expires_in_s)} s idle)` : ''}` : 'Control lock: free';
    } catch { /* offline */ }
  }
}

const eventKey = (e) => `${e.t_s}|${e.kind}|${e.message}`;

// y range: at least `span`, widened to whole steps of a round number.
function niceRange(v, span) {
  let lo = v.min;
  let hi = v.max;
  if (hi - lo < span) { const mid = (lo + hi) / 2; lo = mid - span / 2; hi = mid + span / 2; }
  const raw = (hi - lo) / 4;
  const mag = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((x) => x >= raw);
  return [Math.floor(lo / step) * step, Math.ceil(hi / step) * step];
}
const niceLo = (v, span) => Number(niceRange(v, span)[0].toPrecision(6));
const niceHi = (v, span) => Number(niceRange(v, span)[1].toPrecision(6));
// bench time: "42 s", "12:05"
function clock(v) {
  if (v < 600) return `${Math.round(v)} s`;
  const m = Math.floor(v / 60);
  return `${m}:${String(Math.round(v - 60 * m)).padStart(2, '0')}`;
}

export function escapeHtml(s) {
  return s.replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' }[c]));
}
