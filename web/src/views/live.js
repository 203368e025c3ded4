// Live view: time-series charts of the telemetry (a chosen span of bench time, filled from the
// daemon's history on load, reconnect and after a restart), the scope controls (scope.js), the
// readout (the sweep that runs, the last stop's disable), bench control (setpoints, enable /
// ordered stop, reset, estimator and PWM, control lock; disabled while a sweep owns the bench),
// the feed of the sweep's last points (live_sweep.js) and events.
import { ChartCard, axis } from '../charts.js';
import { api } from '../api.js';
import { faultText } from '../link.js';
import { ESTIMATORS } from '../plan.js';
import { Scope, tooltipFormatter, timeText } from '../scope.js';
import { SweepFeed, sweepRows, sweepActive } from './live_sweep.js';

const KEEP_S = 930;   // the longest span (15 min) and a margin
const GAP_S = 1;      // samples further apart: the line breaks (a daemon restart, a dropped link)
const $ = (s) => document.querySelector(s);
const fmt = (v, d = 1) => (v == null || !Number.isFinite(v) ? '–' : (Math.abs(v) < 0.5 * 10 ** -d ? 0 : v).toFixed(d));

// Setpoints are what the bench commands now (telemetry cmd_*): a sweep's point, its load ramp.
const CHARTS = [
  { id: 'speed', title: 'Speed', unit: 'rpm', series: [['speed_rpm', 'measured'], ['cmd_speed_rpm', 'setpoint', true]], d: 0, span: 100 },
  { id: 'torque', title: 'Load torque', unit: 'N m', series: [['torque_Nm', 'T_L'], ['cmd_load_Nm', 'setpoint', true]], d: 2, span: 0.5 },
  { id: 'angle', title: 'Current angle θ_i', unit: 'deg', series: [['theta_i_deg', 'measured'], ['cmd_angle_deg', 'setpoint', true]], d: 1, span: 5 },
  { id: 'currents', title: 'Currents', unit: 'A', series: [['im_A', 'I_m'], ['id_A', 'i_d'], ['iq_A', 'i_q']], d: 2, span: 0.5 },
  { id: 'udc', title: 'DC bus U_dc', unit: 'V', series: [['udc_V', 'U_dc']], d: 1, span: 10 },
  // Each power as what it is: the drive's own estimate P_ac (telemetry pac_W), and the VFC meter's
  // P_dcM (pdcm_W) only when the daemon sends it live (today's measures it over a point's window).
  { id: 'power', title: 'Power', unit: 'W', series: [['pac_W', 'P_ac (drive estimate)'], ['pdcm_W', 'P_dcM (meter)']], d: 1, span: 20,
    short: ['P_ac', 'P_dcM'] },
  { id: 'temp', title: 'Winding temperature', unit: '°C', series: [['temp_C', 'temperature']], d: 1, span: 2 },
  { id: 'poserr', title: 'Position error', unit: 'deg', series: [['pos_err_deg', 'θ̂ − θ']], d: 2, span: 1, empty: 'no live position error (the encoder is the source, or the daemon does not send it)' },
];
// The CSV's columns: the sample's keys carry their units.
const CSV_COLUMNS = ['t_s', 'speed_rpm', 'cmd_speed_rpm', 'torque_Nm', 'cmd_load_Nm', 'theta_i_deg', 'cmd_angle_deg', 'im_A', 'id_A', 'iq_A',
  'udc_V', 'pac_W', 'pdcm_W', 'temp_C', 'pos_err_deg'].map((k) => [k, k]);

// The measured current angle atan2(|i_q|, i_d) (docs/record.md angle_meas_deg); none below 0.1 A.
const thetaI = (id, iq) => (id == null || iq == null || Math.hypot(id, iq) < 0.1 ? null : (Math.atan2(Math.abs(iq), id) * 180) / Math.PI);

export class LiveView {
  constructor(app) {
    this.app = app;
    this.buf = [];          // telemetry samples
    this.cards = new Map();
    this.dirty = false;
    this.lastT = -Infinity;
    app.live = this; // for the end-to-end tests
    this.scope = new Scope($('#scope-bar'), CHARTS, {
      onChange: () => { this.dirty = true; this.render(true); },
      samples: () => this.buf,
      csvColumns: CSV_COLUMNS,
    });
    this.feed = new SweepFeed();
    const host = $('#live-charts');
    for (const c of CHARTS) {
      const div = document.createElement('div');
      div.className = 'chart-card';
      div.dataset.chart = `live-${c.id}`;
      host.append(div);
      this.cards.set(c.id, new ChartCard(div, { title: `${c.title} [${c.unit}]` }));
    }
    this.titlePower(false);
    this.fillEstimators(false);
    app.on('telemetry', (t) => this.onTelemetry(t));
    app.on('status', (st) => this.onStatus(st));
    app.on('sweep-progress', () => { if (app.status) { this.feed.update(app.status); this.renderReadout(); } });
    app.on('event', (e) => this.addEvents([e]));
    // A new daemon instance: the old one's events are not this one's (one line says why they went).
    app.on('daemon-restarted', () => { this.events = []; this.restartNote = true; this.renderEvents(); });
    app.on('view', ({ view }) => { this.visible = view === 'live'; if (this.visible) this.dirty = true; });
    app.on('refresh', () => { this.refreshLock(); this.fillHistory(); if (!this.estimatorsFromDaemon) this.fillEstimators(true); });
    // Long spans redraw once a second: 15 min are 18000 samples a series.
    setInterval(() => { if (this.scope.span_s <= 60 || ++this.slow % 5 === 0) this.render(); }, 200);
    this.slow = 0;
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
      if (t.t_s != null && t.t_s < this.lastT - 1) { this.buf = []; this.events = []; } // bench clock restarted: the history refills it
      else return;
    }
    this.lastT = t.t_s;
    const cmd = this.app.status?.commanded || {};
    this.titlePower(t.pdcm_W != null);
    const sample = {
      ...t, pac_W: t.pac_W ?? null, pdcm_W: t.pdcm_W ?? null, theta_i_deg: thetaI(t.id_A, t.iq_A),
      cmd_speed_rpm: t.cmd_speed_rpm ?? cmd.speed_rpm, cmd_load_Nm: t.cmd_load_Nm ?? cmd.load_Nm, cmd_angle_deg: t.cmd_angle_deg ?? cmd.angle_deg,
    };
    this.buf.push(sample);
    const cut = t.t_s - KEEP_S;
    if (this.buf.length > 50 && this.buf[0].t_s < cut) this.buf = this.buf.filter((s) => s.t_s >= cut);
    this.latest = sample;
    this.dirty = true;
  }

  // The power chart says which power it draws: the drive's estimate P_ac, and the meter's P_dcM
  // only while the daemon sends it (never the one labelled as the other).
  titlePower(meterLive) {
    if (meterLive === this.meterLive) return;
    this.meterLive = meterLive;
    const h = this.cards.get('power').h;
    h.textContent = meterLive ? 'Power: P_dcM (meter), P_ac (drive estimate) [W]' : 'Drive power P_ac [W] (estimate; no live P_dcM)';
    h.title = meterLive ? 'P_dcM: DC power into the SynRM drive, the VFC meter; P_ac: the drive\'s own output-power estimate'
      : 'The drive\'s own output-power estimate 1.5 (u_d i_d + u_q i_q): the daemon sends no live P_dcM (the VFC meter measures it over each point\'s window)';
  }

  // The daemon's telemetry ring (GET /api/telemetry/history): the charts full at once on load,
  // on reconnect and after a daemon restart (its old trace before a gap); live samples newer than
  // the history's newest are kept.
  async fillHistory() {
    let h;
    try { h = await api('GET', '/api/telemetry/history?span_s=900', undefined, { quiet401: true }); } catch { return; }
    if (!h || !Array.isArray(h.t_s) || !h.t_s.length) return;
    const c = h.channels || {};
    const rows = h.t_s.map((t, i) => {
      const s = { t_s: t, source: 'history' };
      for (const k of Object.keys(c)) s[k] = c[k][i];
      s.pdcm_W = s.pdcm_W ?? null; // the meter's, only when the daemon keeps it
      s.theta_i_deg = thetaI(s.id_A, s.iq_A);
      return s;
    });
    const newest = rows[rows.length - 1].t_s;
    this.buf = rows.concat(this.buf.filter((s) => s.t_s > newest));
    this.lastT = this.buf[this.buf.length - 1].t_s;
    this.latest = this.latest || rows[rows.length - 1];
    this.dirty = true;
    this.render(true);
  }

  render(force = false) {
    if (!this.visible || (!this.dirty && !force)) return;
    this.dirty = false;
    this.renderReadout();
    if (this.scope.frozen && !force) return; // the buffer keeps filling; unfreezing catches up
    if (this.scope.frozen && this.frozenAt != null) { this.draw(this.frozenAt); return; }
    this.frozenAt = this.scope.frozen ? this.lastT : null;
    this.draw(this.lastT);
  }

  // The charts up to bench time `tEnd`: the chosen span, or the whole buffer when it is shorter.
  draw(tEnd) {
    const span = this.scope.span_s;
    const first = this.buf.length ? this.buf[0].t_s : 0;
    const t1 = Math.max(tEnd, first + span);
    const t0 = t1 - span;
    const rows = this.buf.filter((s) => s.t_s >= t0 && s.t_s <= tEnd);
    for (const c of CHARTS) {
      const card = this.cards.get(c.id);
      const shown = this.scope.shown(c.id);
      card.card.hidden = !shown;
      if (!shown) continue;
      const series = c.series.map(([key, name, dashed], i) => ({
        name, type: 'line', showSymbol: false, sampling: 'lttb', connectNulls: false,
        lineStyle: { width: dashed ? 1.5 : 2, type: dashed ? 'dashed' : 'solid' },
        data: withGaps(rows, key),
        ...(i === 0 ? { markLine: this.scope.markLine() } : {}),
      }));
      if (!card.chart) {
        card.set({
          legend: c.series.length > 1 ? { top: 0, right: 70, textStyle: { color: '#14181f' } } : undefined,
          grid: { left: 52, right: 12, top: 26, bottom: 26 },
          tooltip: { trigger: 'axis', confine: true, formatter: tooltipFormatter(c.unit) },
          dataZoom: [{ type: 'inside', xAxisIndex: 0, filterMode: 'none' }],
          xAxis: axis('', { min: t0, max: t1, splitNumber: 4, axisLabel: { color: '#333b47', formatter: clock } }),
          // at least `span` of range, so noise around a constant does not fill the chart
          yAxis: axis('', { min: (v) => niceLo(v, c.span), max: (v) => niceHi(v, c.span) }),
          series,
        }, { empty: c.empty || 'waiting for telemetry' });
        // A click sets a cursor at the clicked bench time.
        card.chart.getZr().on('click', (e) => {
          const [t] = card.chart.convertFromPixel({ gridIndex: 0 }, [e.offsetX, e.offsetY]);
          if (Number.isFinite(t)) this.scope.addCursor(t);
        });
      } else {
        card.update({ xAxis: { min: t0, max: t1 }, series: series.map((s) => ({ data: s.data, ...(s.markLine ? { markLine: s.markLine } : {}) })) });
      }
      card.card.dataset.firstX = rows.length ? String(rows[0].t_s) : '';
      card.card.dataset.lastX = rows.length ? String(rows[rows.length - 1].t_s) : '';
      if (c.short) { // different quantities in one chart: each named, those with a value
        const parts = c.series.map(([key], i) => [c.short[i], this.latest?.[key]]).filter(([, x]) => x != null);
        card.value(parts.length ? parts.map(([n, x]) => `${n} ${fmt(x, c.d)} ${c.unit}`).join(' · ') : '–');
      } else {
        const v = this.latest?.[c.series[0][0]];
        card.value(v == null ? '–' : `${fmt(v, c.d)} ${c.unit}`);
      }
    }
    this.scope.renderCursors();
  }

  // The last value drawn of a chart's series (the end-to-end tests read the chart itself).
  drawnLast(chartId, seriesName) {
    const chart = this.cards.get(chartId)?.chart;
    const s = chart?.getOption().series.find((x) => x.name === seriesName);
    const d = s?.data?.filter((p) => p[1] != null);
    return d?.length ? d[d.length - 1][1] : null;
  }

  onStatus(st) {
    this.status = st;
    this.noteEnabled(st);
    this.renderReadout();
    this.feed.update(st);
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
    const sweep = sweepRows(st);
    const rows = [
      ...(sweep.length ? sweep : [['state', (t ? t.enabled : st.enabled) ? 'enabled' : 'disabled']]),
      ['phase', (t && t.phase) || st.supervisor?.phase || '–'],
      ['speed', `${fmt(v('speed_rpm'), 0)} rpm`],
      ['I_m', `${fmt(v('im_A'), 2)} A`],
      ['load', `${fmt(t?.torque_Nm ?? st.load?.torque_Nm, 2)} N m`],
      ['U_dc', `${fmt(v('udc_V'), 1)} V`],
      ['temperature', `${fmt(v('temp_C'), 1)} °C`],
      [sweepActive(st) ? 'commanded' : 'setpoints', sweepActive(st) && st.commanded
        ? `${fmt(st.commanded.speed_rpm, 0)} rpm, ${fmt(st.commanded.load_Nm, 2)} N m, ${fmt(st.commanded.angle_deg, 1)}°`
        : `${fmt(st.setpoints?.speed_rpm, 0)} rpm, ${fmt(st.setpoints?.load_Nm, 2)} N m, ${fmt(st.setpoints?.angle_deg, 1)}°`],
    ];
    const drive = this.driveConfig(st);
    if (drive) rows.push(['estimator / PWM', drive]);
    if (st.supervisor?.trip) rows.push(['trip', `${faultText(st.supervisor.trip.fault, st.supervisor.trip.fault_code_raw)}: ${st.supervisor.trip.detail}`]);
    if (st.supervisor?.alarm) rows.push(['ALARM', st.supervisor.alarm.detail]);
    // A stop's confirmation belongs to that stop: it goes once the drives were enabled after it.
    const dis = st.supervisor?.disable;
    if (dis && !(this.enabledSeenAt > dis.at_s)) rows.push(['disable', disableText(dis)]);
    if (st.heartbeats === false) rows.push(['heartbeats', "stopped until reset: the drives' watchdogs are armed"]);
    const html = rows.map(([k, val]) => `<dt>${k}</dt><dd data-k="${k}">${escapeHtml(String(val))}</dd>`).join('');
    if (html !== this.readoutHtml) { this.readoutHtml = html; $('#readout').innerHTML = html; }
  }

  // What the SynRM drive runs (or runs on Enable): while a sweep owns the bench its point's
  // configuration (the point procedure writes it before it enables), between two points the last
  // point's; else the manual mode (status mode), which Enable writes. The daemon's status says
  // which configuration it commands only through these two (no field for what the drive was last
  // set to), so between sweeps and manual runs the page does not guess.
  driveConfig(st) {
    const sw = st.sweep;
    if (sweepActive(st)) {
      if (sw.point) { this.lastPoint = { id: sw.id, ...sw.point }; return `${sw.point.estimator} / ${sw.point.pwm} (sweep point)`; }
      const last = this.lastPoint?.id === sw.id ? this.lastPoint : null;
      return last ? `${last.estimator} / ${last.pwm} (the sweep's last point; none in flight)` : '– (the sweep has no point in flight yet)';
    }
    const m = st.mode || (st.estimator ? { estimator: st.estimator, pwm: st.pwm } : null);
    if (!m) return null;
    return st.enabled ? `${m.estimator} / ${m.pwm}` : `${m.estimator} / ${m.pwm} (manual, on Enable)`;
  }

  // The drives are enabled now (by hand, or by a sweep's point in flight): remembered as the
  // bench time, so a stop's disable report older than it is not shown as news.
  noteEnabled(st) {
    // (phase normal: a status published in the tick of a trip or E-stop does not count)
    const on = (st.supervisor?.phase ?? 'normal') === 'normal' && !st.stopping
      && (st.enabled || (sweepActive(st) && st.sweep.current_index != null && st.sweep.point != null));
    if (on && Number.isFinite(st.t_s)) this.enabledSeenAt = Math.max(this.enabledSeenAt ?? -Infinity, st.t_s);
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

// The last stop's disable (status supervisor.disable): both read back, or per drive what is open.
function disableText(d) {
  if (d.confirmed) return `both drives read back disabled (stop at ${timeText(d.at_s)})`;
  const one = (label, x) => `${label} ${x.state}${x.attempts > 1 ? ` (${x.attempts} tries)` : ''}${x.error ? `: ${x.error}` : ''}`;
  return `not confirmed: ${one('SynRM', d.synrm)}, ${one('load', d.load)}`;
}

// [t, value] pairs, a null after a sample followed by a gap, so the line breaks there.
function withGaps(rows, key) {
  const out = [];
  for (let i = 0; i < rows.length; i++) {
    const s = rows[i];
    out.push([s.t_s, s[key] ?? null]);
    if (i + 1 < rows.length && rows[i + 1].t_s - s.t_s > GAP_S) out.push([s.t_s + GAP_S / 2, null]);
  }
  return out;
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
  if (v < 0) return `−${clock(-v)}`;
  if (v < 600) return `${Math.round(v)} s`;
  const m = Math.floor(v / 60);
  return `${m}:${String(Math.round(v - 60 * m)).padStart(2, '0')}`;
}

export function escapeHtml(s) {
  return s.replace(/[&<>"']/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;', "'": '&#39;' }[c]));
}
