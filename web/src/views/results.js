// Results view: one sweep's analysis drawn as the thesis draws it, with exports.
import { api, download, saveBlob, getToken } from '../api.js';
import { ChartCard } from '../charts.js';
import { analysisConfigs } from '../analysis_configs.js';
import { effMapOption, etaOption, trajectoriesOption, curveOption, posErrOption, deltaOption, histOption, cfgLabel } from './plots.js';
import { uncertaintyNote, outcomeNote } from '../uncertainty_note.js';
import { escapeHtml } from './live.js';
import { onBench } from '../bench_label.js';
import { ResultTables } from './tables.js';
import { Compare } from './compare.js';
import { keyboardPoints } from '../chart_keys.js';
import { sweepDate } from '../export_png.js';
import { drawContours } from './contours.js';

const $ = (s) => document.querySelector(s);
const key = (c) => `${c.estimator}/${c.pwm}`;
// #/results/A/vs/B: the sweep compared with A (main.js's route passes A only)
const vsFromHash = () => Number(/^#\/results\/\d+\/vs\/(\d+)/.exec(location.hash)?.[1]) || null;
// file-name part of each card's titled PNG export
const FIGURE = { map: 'efficiency-map', eta: 'efficiency-vs-load', traj: 'mtpa-me-angle', curve: 'im-pdcm-vs-angle', poserr: 'position-error', delta: 'delta-vs-reference', hist: 'histograms' };

export class ResultsView {
  constructor(app) {
    this.app = app;
    this.cards = {
      map: new ChartCard($('[data-chart="r-map"]'), { title: 'Efficiency map P_m / P_dcM at the ME angle' }),
      contour: new ChartCard($('[data-chart="r-contour"]'), { title: 'Efficiency contours (interpolated, iso-η lines)' }),
      eta: new ChartCard($('[data-chart="r-eta"]'), { title: 'Efficiency at the ME angle against load' }),
      traj: new ChartCard($('[data-chart="r-traj"]'), { title: 'MTPA and ME angle against load (Fig. 6.20)' }),
      curve: new ChartCard($('[data-chart="r-curve"]'), { title: 'I_m and P_dcM against angle' }),
      poserr: new ChartCard($('[data-chart="r-poserr"]'), { title: 'Position error against load (Figs. 6.13-6.15)' }),
      delta: new ChartCard($('[data-chart="r-delta"]'), { title: 'ΔI_m (MTPA) and ΔP_dcM (ME) vs reference (Fig. 6.21)' }),
      hist: new ChartCard($('[data-chart="r-hist"]'), { title: 'Histograms (Figs. 6.16-6.19)' }),
    };
    this.sweepId = null;
    this.points = [];
    this.analysis = null;
    for (const [k, c] of Object.entries(this.cards)) {
      keyboardPoints(c);
      c.exportMeta = () => this.exportMeta(c, FIGURE[k], k === 'curve' ? 'all-configurations' : k === 'delta' ? `all-vs-${$('#r-ref').value}` : $('#r-config').value,
        this.sweepName(this.sweepId), (app.sweeps || []).find((s) => s.id === this.sweepId));
    }
    this.tables = new ResultTables($('#r-tables'));
    // The map or the map of its uncertainty u (where the map is uncertain).
    this.showU = false;
    const uBtn = document.createElement('button');
    Object.assign(uBtn, { type: 'button', className: 'small', id: 'r-map-u', textContent: 'map of u', title: 'Show the standard uncertainty u of η per cell instead of η' });
    uBtn.setAttribute('aria-pressed', 'false');
    uBtn.addEventListener('click', () => { this.showU = !this.showU; uBtn.setAttribute('aria-pressed', String(this.showU)); uBtn.textContent = this.showU ? 'map of η' : 'map of u'; this.draw(); });
    this.cards.map.h.parentElement.append(uBtn); // after PNG: "header button" stays the export
    app.resultsView = this; // window.synbench.resultsView: the end-to-end tests read the charts' options
    this.compare = new Compare(this, $('#r-compare'));
    app.on('sweeps', (list) => this.fillSweeps(list));
    app.on('view', async ({ view, arg }) => {
      this.visible = view === 'results';
      if (!this.visible) return;
      await app.refreshSweeps();
      if (arg) this.sweepId = arg;
      this.compare.vsId = arg ? vsFromHash() : null;
      if (!this.sweepId) {
        const done = (app.sweeps || []).filter((s) => s.points_stored > 0);
        this.sweepId = done.length ? done[done.length - 1].id : null;
      }
      this.fillSweeps(app.sweeps || []);
      if (this.sweepId) this.load();
    });
    $('#r-sweep').addEventListener('change', () => { this.sweepId = Number($('#r-sweep').value); this.keepInHash(); this.load(); });
    $('#r-vs').addEventListener('change', () => { this.compare.vsId = Number($('#r-vs').value) || null; this.keepInHash(); this.compare.load(); });
    $('#r-ref').addEventListener('change', () => this.load());
    for (const id of ['#r-config', '#r-speed', '#r-load']) $(id).addEventListener('change', () => this.draw());
    $('#r-speed').addEventListener('change', () => this.fillLoads());
    $('#r-csv').addEventListener('click', () => this.sweepId && download(`/api/sweeps/${this.sweepId}/points?format=csv`, `sweep-${this.sweepId}-points.csv`, 'text/csv')
      .catch((e) => app.toast(`export: ${e.message}`, true)));
    $('#r-json').addEventListener('click', () => this.analysis && saveBlob(new Blob([JSON.stringify(this.analysis, null, 2)], { type: 'application/json' }), `sweep-${this.sweepId}-analysis.json`));
    $('#r-acsv').addEventListener('click', () => this.exportAnalysisCsv());
    $('#r-report').addEventListener('click', () => this.downloadReport());
  }

  fillSweeps(list) {
    const sel = $('#r-sweep');
    const opts = list.slice().reverse().map((s) => `<option value="${s.id}">#${s.id} ${escapeHtml(s.name)}${escapeHtml(onBench(s, list))} (${s.state}, ${s.points_stored} points)</option>`).join('');
    if (sel.innerHTML !== opts) sel.innerHTML = opts || '<option value="">no sweeps yet</option>';
    if (this.sweepId) sel.value = String(this.sweepId);
    const vs = $('#r-vs');
    const vopts = '<option value="">no comparison</option>' + list.slice().reverse().filter((s) => s.points_stored > 0)
      .map((s) => `<option value="${s.id}">#${s.id} ${escapeHtml(s.name)}${escapeHtml(onBench(s, list))}</option>`).join('');
    if (vs.innerHTML !== vopts) vs.innerHTML = vopts;
    vs.value = String(this.compare.vsId || '');
  }

  // The URL says what is shown: #/results/A, or #/results/A/vs/B (a reload or a link shows it).
  keepInHash() {
    const h = `#/results/${this.sweepId}${this.compare.vsId ? `/vs/${this.compare.vsId}` : ''}`;
    if (location.hash !== h) history.replaceState(null, '', h);
  }

  sweepName(id) { return this.compare.sweepName(id); }

  // What a titled PNG export of card says (export_png.js).
  exportMeta(card, figure, config, sweepText, sweep) {
    const date = sweepDate(sweep);
    return { title: card.h.textContent, subtitle: `${sweepText} · configuration ${config.replace('/', ' / ')} · ${date}`,
      sweepId: this.sweepId, figure, config, date };
  }

  refQuery() {
    const r = $('#r-ref').value;
    return r ? `?reference=${r}` : ''; // ESTIMATOR/PWM, [a-z0-9-] only
  }

  async load() {
    const id = this.sweepId;
    if (!id) return;
    $('#r-summary').textContent = 'loading…';
    try {
      const points = await api('GET', `/api/sweeps/${id}/points`);
      const analysis = await api('GET', `/api/sweeps/${id}/analysis${this.refQuery()}`, undefined, { quiet401: true });
      if (id !== this.sweepId) return;
      this.points = points;
      this.analysis = analysis;
      this.fillSelectors();
      this.draw();
      this.compare.load();
      const p = analysis.points || {};
      $('#r-summary').textContent = `Sweep #${id}: ${p.records ?? points.length} points, ${p.used ?? '?'} used`
        + `${p.excluded?.length ? `, ${p.excluded.length} left out (unstable, faulted or voltage-limited)` : ''}`;
      $('#r-unote').textContent = uncertaintyNote(points, analysis);
      const outcome = outcomeNote(analysis?.sweep_outcome);
      $('#r-outcome').hidden = !outcome;
      $('#r-outcome').textContent = outcome;
    } catch (e) {
      $('#r-summary').textContent = `cannot load sweep ${id}: ${e.message}`;
    }
  }

  fillSelectors() {
    const cfgs = analysisConfigs(this.analysis);
    const fromPoints = [];
    for (const p of this.points) if (!fromPoints.some((c) => key(c) === key(p))) fromPoints.push({ estimator: p.estimator, pwm: p.pwm });
    const all = cfgs.length ? cfgs : fromPoints;
    const setOpts = (sel, items, keep) => {
      const prev = sel.value;
      sel.innerHTML = items.map(([v, t]) => `<option value="${escapeHtml(String(v))}">${escapeHtml(t)}</option>`).join('');
      if (keep && items.some(([v]) => String(v) === prev)) sel.value = prev;
    };
    // Default: an estimator with a position estimate when there is one (it has every plot).
    const prevCfg = $('#r-config').value;
    setOpts($('#r-config'), all.map((c) => [key(c), cfgLabel(c)]), true);
    if (!prevCfg) {
      const est = all.find((c) => c.estimator !== 'encoder');
      if (est) $('#r-config').value = key(est);
    }
    const ref = this.analysis?.options?.reference;
    setOpts($('#r-ref'), all.map((c) => [key(c), `reference: ${cfgLabel(c)}`]), false);
    if (ref) $('#r-ref').value = key(ref);
    const speeds = [...new Set(this.points.map((p) => p.speed_rpm))].sort((a, b) => a - b);
    setOpts($('#r-speed'), speeds.map((s) => [s, `${s}`]), true);
    this.fillLoads();
  }

  fillLoads() {
    const speed = Number($('#r-speed').value);
    const loads = [...new Set(this.points.filter((p) => p.speed_rpm === speed).map((p) => p.load_Nm))].sort((a, b) => a - b);
    const sel = $('#r-load');
    const prev = sel.value;
    sel.innerHTML = loads.map((l) => `<option value="${l}">${l}</option>`).join('');
    if (loads.map(String).includes(prev)) sel.value = prev;
    this.draw();
  }

  draw() {
    if (!this.analysis) return;
    const [estimator, pwm] = ($('#r-config').value || 'encoder/capwm').split('/');
    const cfg = { estimator, pwm };
    const a = this.analysis;
    const speed = Number($('#r-speed').value);
    const load = Number($('#r-load').value);
    this.cards.map.set(effMapOption(a, cfg, this.showU), { empty: this.showU ? 'no uncertainty stored' : 'no data yet' });
    this.cards.map.h.textContent = `${this.showU ? 'Standard uncertainty u of the efficiency map' : 'Efficiency map η = P_m / P_dcM'} at the ME angle, ${cfgLabel(cfg)}`;
    this.cards.eta.set(etaOption(a, cfg));
    this.cards.eta.h.textContent = `Efficiency η at the ME angle against load, ${cfgLabel(cfg)}`;
    drawContours(this.cards.contour, a, cfg, cfgLabel(cfg));
    this.cards.traj.set(trajectoriesOption(a, cfg));
    this.cards.traj.h.textContent = `MTPA (solid) and ME (dashed) angle against load, ${cfgLabel(cfg)}`;
    this.cards.curve.set(curveOption(this.points, a, speed, load, analysisConfigs(a).length ? analysisConfigs(a) : [cfg]));
    this.cards.curve.h.textContent = `I_m and P_dcM against angle at ${speed} rpm, ${load} N m`;
    this.cards.poserr.set(posErrOption(a, cfg), { empty: estimator === 'encoder' ? 'the encoder has no position error: choose an estimator' : 'no position error in this sweep' });
    this.cards.poserr.h.textContent = `Position error min / mean / max against load, ${cfgLabel(cfg)} (Figs. 6.13-6.15)`;
    this.cards.delta.set(deltaOption(a), { empty: 'needs a second configuration measured at the reference\'s speeds and loads' });
    this.cards.hist.set(histOption(a, cfg), { empty: estimator === 'encoder' ? 'the encoder estimates nothing: choose an estimator' : 'no estimates in this sweep' });
    this.cards.hist.h.textContent = `Histograms, ${cfgLabel(cfg)} (Figs. 6.16-6.19)`;
    this.tables.render(a, cfg);
    this.compare.draw(cfg, speed, load);
  }

  // The report (docs/report.md) and its CSV, each saved under the name the daemon gives.
  async downloadReport() {
    const id = this.sweepId;
    if (!id) return;
    try {
      for (const [path, type] of [[`/api/sweeps/${id}/report`, 'text/html'], [`/api/sweeps/${id}/report.csv`, 'text/csv']]) {
        const res = await fetch(path, { headers: { Authorization: `Bearer ${getToken()}` }, cache: 'no-store' });
        if (!res.ok) throw new Error(`${path}: HTTP ${res.status}`);
        const name = /filename="([^"]+)"/.exec(res.headers.get('Content-Disposition') || '')?.[1] || `sweep-${id}-report${type === 'text/csv' ? '.csv' : '.html'}`;
        saveBlob(new Blob([await res.text()], { type }), name);
      }
    } catch (e) {
      this.app.toast(`report: ${e.message}`, true);
    }
  }

  async exportAnalysisCsv() {
    if (!this.sweepId) return;
    try {
      await download(`/api/sweeps/${this.sweepId}/analysis?format=csv${this.refQuery().replace('?', '&')}`, `sweep-${this.sweepId}-analysis.csv`, 'text/csv');
    } catch (e) {
      if (e.status !== 404 && e.status !== 405) { this.app.toast(`export: ${e.message}`, true); return; }
      // No CSV route: the curves (MTPA and ME per configuration, speed, load) from the analysis.
      const head = 'estimator,pwm,speed_rpm,load_Nm,points,mtpa_angle_deg,mtpa_im_A,mtpa_pdcm_W,mtpa_efficiency,me_angle_deg,me_im_A,me_pdcm_W,me_efficiency';
      const rows = (this.analysis?.curves?.entries || []).map((c) => [c.estimator, c.pwm, c.speed_rpm, c.load_Nm, c.points,
        c.mtpa.angle_deg, c.mtpa.im_A, c.mtpa.pdcm_W, c.mtpa.efficiency, c.me.angle_deg, c.me.im_A, c.me.pdcm_W, c.me.efficiency].join(','));
      saveBlob(new Blob([[head, ...rows].join('\n') + '\n'], { type: 'text/csv' }), `sweep-${this.sweepId}-analysis.csv`);
    }
  }
}
