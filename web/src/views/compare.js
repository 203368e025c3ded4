// Comparing two runs in the Results view (#/results/A/vs/B): both runs' MTPA/ME trajectories and
// I_m/P_dcM curves of the chosen configuration on one chart each, labelled "sweep #A ..." and
// "sweep #B ...", and the difference B - A per configuration x speed x load (MTPA angle, ME angle,
// η and P_dcM at ME) as a chart and a table; points measured in only one run are listed as such.
// Each difference carries u(diff) = sqrt(uA^2 + uB^2) of the point-to-point parts (one bench: the
// calibration is common and cancels) and whether it is significant at 95 % (|diff| > 1.96 u);
// insignificant bars are faded and hatched.
// Both analyses come from GET /api/sweeps/{id}/analysis: the page only subtracts.
import { onBench } from '../bench_label.js';
import { api } from '../api.js';
import { ChartCard, axis, PALETTE } from '../charts.js';
import { analysisConfigs } from '../analysis_configs.js';
import { trajectoriesOption, curveOption, cfgLabel } from './plots.js';
import { tableBlock, numCell, textCell, uCell, sigCell } from './tables.js';
import { errorBarSeries, withoutBars, known, fmtU, sigText, BARS_NOTE, NO_U_NOTE, FADED, FADED_NOTE } from '../errorbars.js';
import { keyboardPoints } from '../chart_keys.js';

const ckey = (c) => `${c.estimator}/${c.pwm}`;
const pkey = (c) => `${ckey(c)}|${c.speed_rpm}|${c.load_Nm}`;
const sub = (b, a) => (a == null || b == null || !Number.isFinite(a) || !Number.isFinite(b) ? null : b - a);
const r4 = (v) => (v == null ? null : Number(v.toFixed(4)));
export const uDiff = (ua, ub) => (known(ua) && known(ub) ? Math.hypot(ua, ub) : null);
// The optimum's point-to-point u when the analysis gives it (`pdcm_u_repeat_W`), else its combined u (larger: no false "significant").
const repeatU = (o, q, unit = '') => o?.[`${q}_u_repeat${unit}`] ?? o?.[`${q}_u${unit}`] ?? null;
// |d| > 1.96 u(d): significant at 95 %; null when either is unknown
export const significant = (d, u) => (d == null || !known(u) ? null : Math.abs(d) > 1.96 * u);

// Every (configuration, speed, load) curve of a and b: the differences b - a where both have it,
// else the run that has it. Sorted by configuration (thesis order), speed, load.
export function diffRuns(a, b) {
  const ea = new Map((a?.curves?.entries || []).map((e) => [pkey(e), e]));
  const eb = new Map((b?.curves?.entries || []).map((e) => [pkey(e), e]));
  const order = analysisConfigs({ curves: { entries: [...ea.values(), ...eb.values()] } }).map(ckey);
  const rows = [];
  for (const k of new Set([...ea.keys(), ...eb.keys()])) {
    const x = ea.get(k);
    const y = eb.get(k);
    const e = x || y;
    const row = { estimator: e.estimator, pwm: e.pwm, speed_rpm: e.speed_rpm, load_Nm: e.load_Nm, in: x && y ? 'both' : x ? 'a' : 'b' };
    if (x && y) {
      row.mtpa_angle_deg = sub(y.mtpa?.angle_deg, x.mtpa?.angle_deg);
      row.me_angle_deg = sub(y.me?.angle_deg, x.me?.angle_deg);
      const eff = sub(y.me?.efficiency, x.me?.efficiency);
      row.me_efficiency_pp = eff == null ? null : eff * 100;
      row.me_pdcm_W = sub(y.me?.pdcm_W, x.me?.pdcm_W);
      // u(diff) = sqrt(uA^2 + uB^2) of the point-to-point parts (one bench: the systematic parts cancel)
      row.mtpa_angle_u_deg = uDiff(x.mtpa_angle_u_deg, y.mtpa_angle_u_deg);
      row.me_angle_u_deg = uDiff(x.me_angle_u_deg, y.me_angle_u_deg);
      const ue = uDiff(repeatU(x.me, 'efficiency'), repeatU(y.me, 'efficiency'));
      row.me_efficiency_u_pp = ue == null ? null : ue * 100;
      row.me_pdcm_u_W = uDiff(repeatU(x.me, 'pdcm', '_W'), repeatU(y.me, 'pdcm', '_W'));
      row.mtpa_angle_significant = significant(row.mtpa_angle_deg, row.mtpa_angle_u_deg);
      row.me_angle_significant = significant(row.me_angle_deg, row.me_angle_u_deg);
      row.me_efficiency_significant = significant(row.me_efficiency_pp, row.me_efficiency_u_pp);
      row.me_pdcm_significant = significant(row.me_pdcm_W, row.me_pdcm_u_W);
    }
    rows.push(row);
  }
  return rows.sort((p, q) => order.indexOf(ckey(p)) - order.indexOf(ckey(q)) || p.speed_rpm - q.speed_rpm || p.load_Nm - q.load_Nm);
}

// The difference chart of one configuration: three panels over (speed, load).
function diffOption(rows, cfg, ida, idb) {
  const rs = rows.filter((r) => r.in === 'both' && ckey(r) === ckey(cfg));
  const cats = rs.map((r) => `${r.speed_rpm} rpm\n${r.load_Nm} N m`);
  // f: the difference's field; its u is f with _u before the unit, its significance f's stem + _significant
  const uf = (f) => f.replace(/_(deg|pp|W)$/, '_u_$1');
  const sf = (f) => f.replace(/_(deg|pp|W)$/, '_significant');
  const bar = (name, f, k, color) => ({ name, type: 'bar', xAxisIndex: k, yAxisIndex: k, color,
    data: rs.map((r) => (r[f] == null ? null : { value: r4(r[f]), u: r[uf(f)], significant: r[sf(f)], itemStyle: r[sf(f)] === false ? FADED : undefined })) });
  const slots = [2, 1, 1];
  const eb = (f, k, slot) => errorBarSeries(`±2u ${f}`, '#14181f', rs.map((r, i) => ({ x: i, y: r[f], u: r[uf(f)] })), { xAxisIndex: k, yAxisIndex: k, slot: { k: slot, n: slots[k] } });
  const bars = [eb('mtpa_angle_deg', 0, 0), eb('me_angle_deg', 0, 1), eb('me_efficiency_pp', 1, 0), eb('me_pdcm_W', 2, 0)].filter(Boolean);
  const faded = rs.some((r) => ['mtpa_angle', 'me_angle', 'me_efficiency', 'me_pdcm'].some((f) => r[`${f}_significant`] === false));
  const tip = (params) => [].concat(params).filter((p) => p.seriesType === 'bar' && p.data).map((p, i) => `${i ? '' : `${p.name.replace('\n', ', ')}<br>`}${p.marker}${p.seriesName}: `
    + `${p.data.value}${known(p.data.u) ? ` ± ${fmtU(p.data.u)} (k=1)` : ''} — ${sigText(p.data.significant)}`).join('<br>');
  const grid = [0, 1, 2].map((k) => ({ left: 64, right: 16, top: `${14 + k * 28}%`, height: '18%' }));
  // panel names above each panel: rotated axis names do not fit three panels
  const panelTitle = (text, k) => ({ text, left: 64, top: `${8 + k * 28}%`, textStyle: { fontSize: 11, fontWeight: 600, color: '#333b47' } });
  return {
    legend: { top: 0, type: 'scroll', textStyle: { color: '#14181f' }, data: ['Δ MTPA angle', 'Δ ME angle', 'Δη at ME', 'ΔP_dcM at ME'] },
    title: [{ text: `#${idb} − #${ida}`, right: 8, top: 0, textStyle: { fontSize: 11, color: '#4a5361', fontWeight: 'normal' } },
      { text: bars.length ? `${BARS_NOTE}${faded ? ` · ${FADED_NOTE}` : ''}` : NO_U_NOTE, right: 8, top: 18, textStyle: { fontSize: 11, color: '#4a5361', fontWeight: 'normal' } },
      panelTitle('Δ MTPA and Δ ME angle [deg]', 0), panelTitle('Δη at ME [percentage points]', 1), panelTitle('ΔP_dcM at ME [W]', 2)],
    tooltip: { trigger: 'axis', formatter: tip },
    grid,
    xAxis: [0, 1, 2].map((k) => ({ type: 'category', data: cats, gridIndex: k, axisLabel: { show: k === 2, color: '#333b47', fontSize: 10 } })),
    yAxis: [axis('Δ angle [deg]', { gridIndex: 0, scale: false, nameTextStyle: { color: 'rgba(0,0,0,0)' } }), axis('Δη at ME [pp]', { gridIndex: 1, scale: false, nameTextStyle: { color: 'rgba(0,0,0,0)' } }),
      axis('ΔP_dcM at ME [W]', { gridIndex: 2, scale: false, nameTextStyle: { color: 'rgba(0,0,0,0)' } })],
    series: [bar('Δ MTPA angle', 'mtpa_angle_deg', 0, PALETTE[0]), bar('Δ ME angle', 'me_angle_deg', 0, PALETTE[1]),
      bar('Δη at ME', 'me_efficiency_pp', 1, PALETTE[2]), bar('ΔP_dcM at ME', 'me_pdcm_W', 2, PALETTE[3]), ...bars],
  };
}

// Series of two runs' options on one chart: names prefixed with the run, colours told apart.
function overlay(oa, ob, ida, idb, label) {
  const tag = (o, id, run) => withoutBars(o.series).map((s, k) => ({ ...s, name: `sweep #${id} ${label} · ${s.name.replace(` ${label}`, '')}`, color: PALETTE[(2 * Math.floor(k / 2) + run) % PALETTE.length] }));
  return { ...oa, series: [...tag(oa, ida, 0), ...tag(ob, idb, 1)] };
}

export class Compare {
  // results: the ResultsView (its sweepId, points, analysis, app)
  constructor(results, panel) {
    this.r = results;
    this.panel = panel;
    this.vsId = null;
    this.b = null; // {id, points, analysis}
    panel.innerHTML = `<h2 id="h-compare">Comparison</h2><p class="muted" id="r-cmp-note"></p>
      <div class="results-grid"><div class="chart-card" data-chart="r-cmp-traj"></div><div class="chart-card" data-chart="r-cmp-curve"></div>
      <div class="chart-card wide" data-chart="r-cmp-diff"></div></div>`;
    const card = (name, title) => { const c = new ChartCard(panel.querySelector(`[data-chart="${name}"]`), { title }); keyboardPoints(c); return c; };
    this.cards = { traj: card('r-cmp-traj', 'MTPA and ME angle against load, two runs'),
      curve: card('r-cmp-curve', 'I_m and P_dcM against angle, two runs'), diff: card('r-cmp-diff', 'Difference of the two runs') };
    this.table = tableBlock(panel, 'r-cmp-table', 'Difference per configuration, speed and load');
  }

  // Loads the second run when it changed, then draws; hides the panel without one.
  async load() {
    const id = this.vsId;
    if (!id || !this.r.sweepId) { this.b = null; this.panel.hidden = true; return; }
    if (this.b?.id !== id) {
      try {
        const [points, analysis] = await Promise.all([api('GET', `/api/sweeps/${id}/points`), api('GET', `/api/sweeps/${id}/analysis`)]);
        if (id !== this.vsId) return;
        this.b = { id, points, analysis };
      } catch (e) {
        this.b = null;
        this.panel.hidden = false;
        this.panel.querySelector('#r-cmp-note').textContent = `cannot load sweep ${id}: ${e.message}`;
        return;
      }
    }
    this.r.draw();
  }

  sweepName(id) {
    const all = this.r.app.sweeps || [];
    const s = all.find((x) => x.id === id);
    return s ? `sweep #${id} “${s.name}”${onBench(s, all)}` : `sweep #${id}`;
  }

  draw(cfg, speed, load) {
    if (!this.vsId) { this.panel.hidden = true; return; }
    if (this.b?.id !== this.vsId || !this.r.analysis) return; // still loading, or the load failed (its note stays)
    this.panel.hidden = false;
    const ida = this.r.sweepId;
    const idb = this.b.id;
    const a = this.r.analysis;
    const b = this.b.analysis;
    const label = cfgLabel(cfg);
    const inB = analysisConfigs(b).some((c) => ckey(c) === ckey(cfg));
    this.panel.querySelector('#h-compare').textContent = `Comparison: ${this.sweepName(ida)} vs ${this.sweepName(idb)}`;
    this.panel.querySelector('#r-cmp-note').textContent = inB ? `Differences are #${idb} − #${ida}; the charts show ${label}.`
      : `${this.sweepName(idb)} has no ${label}: only its other configurations are in the table.`;
    this.cards.traj.set(overlay(trajectoriesOption(a, cfg), inB ? trajectoriesOption(b, cfg) : { series: [] }, ida, idb, label));
    this.cards.traj.h.textContent = `MTPA (solid) and ME (dashed) angle against load, ${label}: #${ida} and #${idb}`;
    this.cards.curve.set(overlay(curveOption(this.r.points, a, speed, load, [cfg]), curveOption(this.b.points, b, speed, load, [cfg]), ida, idb, label),
      { empty: `no curve at ${speed} rpm, ${load} N m` });
    this.cards.curve.h.textContent = `I_m and P_dcM against angle at ${speed} rpm, ${load} N m, ${label}: #${ida} and #${idb}`;
    const rows = diffRuns(a, b);
    this.cards.diff.set(diffOption(rows, cfg, ida, idb), { empty: 'no (speed, load) measured in both runs' });
    this.cards.diff.h.textContent = `Difference #${idb} − #${ida} per speed and load, ${label}`;
    const where = { a: `only in #${ida}`, b: `only in #${idb}`, both: 'both' };
    this.table.set({
      head: ['configuration', 'speed [rpm]', 'load [N m]', 'measured', 'Δ MTPA angle [deg]', 'Δ ME angle [deg]', 'Δη at ME [pp]', 'ΔP_dcM at ME [W]',
        'u(Δ MTPA angle) [deg]', 'u(Δ ME angle) [deg]', 'u(Δη) [pp]', 'u(ΔP_dcM) [W]', 'significant at 95 % (MTPA angle, ME angle, η, P_dcM)'],
      rowHead: 3,
      rows: rows.map((r) => [textCell(cfgLabel(r)), numCell(r.speed_rpm, 0), numCell(r.load_Nm, 2), textCell(where[r.in]),
        numCell(r.mtpa_angle_deg, 2), numCell(r.me_angle_deg, 2), numCell(r.me_efficiency_pp, 2), numCell(r.me_pdcm_W, 2),
        uCell(r.mtpa_angle_u_deg), uCell(r.me_angle_u_deg), uCell(r.me_efficiency_u_pp), uCell(r.me_pdcm_u_W),
        textCell(r.in === 'both' ? ['mtpa_angle', 'me_angle', 'me_efficiency', 'me_pdcm'].map((f) => sigCell(r[`${f}_significant`]).t).join(', ') : '–')]),
    }, `Difference #${idb} − #${ida} per configuration, speed and load`);
    const date = (id) => (this.r.app.sweeps || []).find((x) => x.id === id);
    for (const [k, figure] of [['traj', 'mtpa-me-angle'], ['curve', 'im-pdcm-vs-angle'], ['diff', 'difference']]) {
      this.cards[k].exportMeta = () => this.r.exportMeta(this.cards[k], `${figure}-vs-${idb}`, ckey(cfg),
        `${this.sweepName(ida)} vs ${this.sweepName(idb)}`, date(ida));
    }
  }
}
