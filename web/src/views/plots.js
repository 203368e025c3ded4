// ECharts options of the result plots, shared by the progress panel and the results view. Input
// is the analysis JSON (docs/analysis.md) or the points JSON (docs/record.md).
import { axis, PALETTE } from '../charts.js';
import { errorBarSeries, pm, fmtU, known, BARS_NOTE, NO_U_NOTE, FADED, FADED_NOTE } from '../errorbars.js';
import { etaRangePct, etaVisualMap } from '../eta_scale.js';

const r2 = (v, d = 2) => (v == null || !Number.isFinite(v) ? null : Number(v.toFixed(d)));
export const sameCfg = (a, b) => a && b && a.estimator === b.estimator && a.pwm === b.pwm;
export const cfgLabel = (c) => `${c.estimator} / ${c.pwm}`;

// The chart's note on its bars: "bars: ±2u, 95 %" when any bar is drawn, else "no uncertainty stored".
export const uNote = (series, extra = '') => ({ text: series.some((s) => s?.errorBars) ? `${BARS_NOTE}${extra}` : NO_U_NOTE,
  right: 8, bottom: 0, textStyle: { fontSize: 11, fontWeight: 'normal', color: '#4a5361' } });
// Axis tooltip lines "● name: value ± u unit (k=1)" of the series that are not error bars.
const uTooltip = (unitOf, digits) => (params) => [].concat(params).filter((p) => p.seriesType !== 'custom' && p.value != null)
  .map((p, k) => `${k === 0 ? `${Array.isArray(p.value) ? p.value[0] : p.name}<br>` : ''}${p.marker}${p.seriesName}: `
    + `${pm(Array.isArray(p.value) ? p.value[1] : p.value, p.data?.u, unitOf(p), digits(p))}${p.data?.significant === false ? ' — not significant at 95 %' : ''}`)
  .join('<br>');

// Efficiency map (P_m / P_dcM at the ME angle) over speed (x) x load torque (y), as the contour
// map and the report draw it, a heat map with the value in each cell, in the one colour scale of
// every efficiency map (eta_scale.js). showU: the map of the efficiency's standard uncertainty u
// (percentage points) instead of η, in a scale of its own (another quantity).
export function effMapOption(analysis, cfg, showU = false) {
  const e = (analysis?.efficiency_map?.entries || []).find((x) => sameCfg(x, cfg)) || analysis?.efficiency_map?.entries?.[0];
  if (!e) return { series: [] };
  const data = [];
  e.speeds_rpm.forEach((s, i) => e.loads_Nm.forEach((l, j) => {
    const v = e.efficiency[i]?.[j];
    const u = e.efficiency_u?.[i]?.[j];
    const shown = showU ? (known(u) ? r2(u * 100, 4) : null) : r2(v * 100, 1);
    if (v != null && shown != null) data.push({ value: [i, j, shown], eta: v, u: known(u) ? u : null, ur: e.efficiency_u_repeat?.[i]?.[j] ?? null });
  }));
  const vals = data.map((d) => d.value[2]);
  const tip = (p) => `${e.speeds_rpm[p.value[0]]} rpm, ${e.loads_Nm[p.value[1]]} N m<br>η = ${known(p.data.u) ? `${(p.data.eta * 100).toFixed(2)} ± ${fmtU(p.data.u * 100)} % (k=1)`
    + `${known(p.data.ur) ? `<br>point-to-point part ${fmtU(p.data.ur * 100)} %` : ''}` : `${(p.data.eta * 100).toFixed(1)} % (${NO_U_NOTE})`}`;
  const hi = vals.length ? Math.max(...vals) : 1;
  const cat = (name, values, gap) => ({ type: 'category', name, nameLocation: 'middle', nameGap: gap, data: values.map(String),
    axisLabel: { color: '#333b47' }, nameTextStyle: { color: '#333b47', fontWeight: 600 } });
  return {
    title: { ...uNote([]), text: !data.some((d) => d.u != null) ? NO_U_NOTE : showU ? 'u(η) per cell, percentage points (k=1)' : 'tooltip: η ± u (k=1)' },
    tooltip: { trigger: 'item', formatter: tip },
    grid: { left: 64, right: 80, top: 24, bottom: 40 },
    xAxis: cat('speed [rpm]', e.speeds_rpm, 26),
    yAxis: cat('load torque T_L [N m]', e.loads_Nm, 40),
    visualMap: showU
      ? { dimension: 2, precision: 2, min: 0, max: hi > 0 ? hi : 1, calculable: true, orient: 'vertical', right: 4, top: 'middle', itemHeight: 160,
        text: ['u(η) %', ''], textStyle: { color: '#14181f' }, inRange: { color: ['#ffffe5', '#fee391', '#fe9929', '#cc4c02', '#662506'] } }
      : etaVisualMap(etaRangePct(e), 2),
    series: [{ name: `${showU ? 'u of the efficiency' : 'efficiency'} ${cfgLabel(e)}`, type: 'heatmap', data,
      label: { show: data.length <= 80, color: '#000', textBorderColor: '#fff', textBorderWidth: 2, fontWeight: 600, formatter: (p) => (showU ? fmtU(p.value[2]) : p.value[2].toFixed(1)) },
      emphasis: { itemStyle: { borderColor: '#000', borderWidth: 1 } } }],
  };
}

// Efficiency at the ME angle against load, one line per speed, with its error bars (the map's cells).
export function etaOption(analysis, cfg) {
  const e = (analysis?.efficiency_map?.entries || []).find((x) => sameCfg(x, cfg)) || analysis?.efficiency_map?.entries?.[0];
  if (!e) return { series: [] };
  const series = [];
  const bars = [];
  e.speeds_rpm.forEach((s, i) => {
    const color = PALETTE[i % PALETTE.length];
    const pts = e.loads_Nm.map((l, j) => ({ x: l, y: e.efficiency[i]?.[j] == null ? null : e.efficiency[i][j] * 100,
      u: known(e.efficiency_u?.[i]?.[j]) ? e.efficiency_u[i][j] * 100 : null })).filter((q) => q.y != null);
    series.push({ name: `η ${s} rpm`, type: 'line', color, symbol: 'circle', symbolSize: 7, data: pts.map((q) => ({ value: [q.x, r2(q.y, 3)], u: q.u })) });
    bars.push(errorBarSeries(`±2u η ${s} rpm`, color, pts));
  });
  series.push(...bars.filter(Boolean));
  return {
    legend: { top: 0, type: 'scroll', textStyle: { color: '#14181f' }, data: series.filter((x) => !x.errorBars).map((x) => x.name) },
    title: uNote(series),
    grid: { left: 56, right: 16, top: 40, bottom: 40 },
    tooltip: { trigger: 'axis', formatter: uTooltip(() => '%', () => 2) },
    xAxis: axis('load torque T_L [N m]', { nameGap: 26 }),
    yAxis: axis('efficiency η at ME [%]', { nameGap: 40 }),
    series,
  };
}

// MTPA (solid) and ME (dashed) angle against load, one colour per speed.
export function trajectoriesOption(analysis, cfg) {
  let curves = (analysis?.curves?.entries || []).filter((c) => sameCfg(c, cfg));
  if (!curves.length && analysis?.curves?.entries?.length) {
    const first = analysis.curves.entries[0];
    curves = analysis.curves.entries.filter((c) => sameCfg(c, first));
  }
  const speeds = [...new Set(curves.map((c) => c.speed_rpm))].sort((a, b) => a - b);
  const series = [];
  const bars = []; // after every line: the keyboard reader walks the lines first
  speeds.forEach((s, k) => {
    const cs = curves.filter((c) => c.speed_rpm === s).sort((a, b) => a.load_Nm - b.load_Nm);
    const color = PALETTE[k % PALETTE.length];
    const pt = (c, o, uk) => ({ value: [c.load_Nm, r2(c[o]?.angle_deg)], u: c[uk] ?? null });
    series.push({ name: `MTPA ${s} rpm`, type: 'line', color, symbol: 'circle', symbolSize: 7, data: cs.map((c) => pt(c, 'mtpa', 'mtpa_angle_u_deg')) });
    series.push({ name: `ME ${s} rpm`, type: 'line', color, symbol: 'diamond', symbolSize: 8, lineStyle: { type: 'dashed' }, data: cs.map((c) => pt(c, 'me', 'me_angle_u_deg')) });
    bars.push(errorBarSeries(`±2u MTPA ${s} rpm`, color, cs.map((c) => ({ x: c.load_Nm, y: c.mtpa?.angle_deg, u: c.mtpa_angle_u_deg }))));
    bars.push(errorBarSeries(`±2u ME ${s} rpm`, color, cs.map((c) => ({ x: c.load_Nm, y: c.me?.angle_deg, u: c.me_angle_u_deg }))));
  });
  series.push(...bars.filter(Boolean));
  return {
    legend: { top: 0, type: 'scroll', textStyle: { color: '#14181f' }, data: series.filter((x) => !x.errorBars).map((x) => x.name) },
    title: uNote(series),
    grid: { left: 56, right: 16, top: 40, bottom: 40 },
    tooltip: { trigger: 'axis', formatter: uTooltip(() => '°', () => 2) },
    xAxis: axis('load torque T_L [N m]', { nameGap: 26 }),
    yAxis: axis('current angle θ_i [deg]', { nameGap: 36 }),
    series,
  };
}

// I_m (left axis) and P_dcM (right axis) against the current angle at one (speed, load), one
// colour per configuration; MTPA and ME optima marked.
export function curveOption(points, analysis, speed, load, configs) {
  const at = points.filter((p) => p.speed_rpm === speed && p.load_Nm === load);
  const series = [];
  const bars = [];
  configs.forEach((cfg, k) => {
    const rs = at.filter((p) => sameCfg(p, cfg)).sort((a, b) => a.angle_deg - b.angle_deg);
    if (!rs.length) return;
    const color = PALETTE[k % PALETTE.length];
    const c = (analysis?.curves?.entries || []).find((x) => sameCfg(x, cfg) && x.speed_rpm === speed && x.load_Nm === load);
    const mark = (o, axisName) => (o ? { symbol: 'pin', symbolSize: 36, label: { fontSize: 10, color: '#fff' },
      data: [{ name: axisName, coord: [r2(o.angle_deg), r2(axisName === 'MTPA' ? o.im_A : o.pdcm_W, 3)], value: axisName }] } : undefined);
    series.push({ name: `I_m ${cfgLabel(cfg)}`, type: 'line', color, yAxisIndex: 0, symbol: 'circle', symbolSize: 6,
      data: rs.map((p) => ({ value: [p.angle_deg, r2(p.im_A, 4)], u: p.im_u_A ?? null })), markPoint: mark(c?.mtpa, 'MTPA') });
    series.push({ name: `P_dcM ${cfgLabel(cfg)}`, type: 'line', color, yAxisIndex: 1, symbol: 'rect', symbolSize: 6, lineStyle: { type: 'dashed' },
      data: rs.map((p) => ({ value: [p.angle_deg, r2(p.pdcm_W, 2)], u: p.pdcm_u_W ?? null })), markPoint: mark(c?.me, 'ME') });
    bars.push(errorBarSeries(`±2u I_m ${cfgLabel(cfg)}`, color, rs.map((p) => ({ x: p.angle_deg, y: p.im_A, u: p.im_u_A })), { yAxisIndex: 0 }));
    bars.push(errorBarSeries(`±2u P_dcM ${cfgLabel(cfg)}`, color, rs.map((p) => ({ x: p.angle_deg, y: p.pdcm_W, u: p.pdcm_u_W })), { yAxisIndex: 1 }));
  });
  series.push(...bars.filter(Boolean));
  return {
    legend: { top: 0, type: 'scroll', textStyle: { color: '#14181f' }, data: series.filter((x) => !x.errorBars).map((x) => x.name) },
    title: uNote(series),
    tooltip: { trigger: 'axis', formatter: uTooltip((p) => (p.seriesName.startsWith('I_m') ? 'A' : 'W'), (p) => (p.seriesName.startsWith('I_m') ? 4 : 2)) },
    grid: { left: 56, right: 60, top: 40, bottom: 40 },
    xAxis: axis('current angle θ_i [deg]', { nameGap: 26 }),
    yAxis: [axis('I_m [A] (solid)', { nameGap: 40 }), axis('P_dcM [W] (dashed)', { nameGap: 44, splitLine: { show: false } })],
    series,
  };
}

// Position error min / mean / max (of the window means) against load, one colour per speed
// (thesis Figs. 6.13-6.15); faint window extremes.
export function posErrOption(analysis, cfg) {
  const es = (analysis?.position_error?.entries || []).filter((e) => sameCfg(e, cfg)).sort((a, b) => a.speed_rpm - b.speed_rpm);
  const series = [];
  es.forEach((e, k) => {
    const color = PALETTE[k % PALETTE.length];
    const d = (f) => e.loads.map((l) => [l.load_Nm, r2(l[f], 3)]);
    series.push({ name: `mean ${e.speed_rpm} rpm`, type: 'line', color, symbol: 'circle', symbolSize: 7, data: d('mean_deg') });
    series.push({ name: `min ${e.speed_rpm} rpm`, type: 'scatter', color, symbol: 'triangle', symbolRotate: 180, symbolSize: 9, data: d('min_deg') });
    series.push({ name: `max ${e.speed_rpm} rpm`, type: 'scatter', color, symbol: 'triangle', symbolSize: 9, data: d('max_deg') });
  });
  return {
    // one legend entry per speed (its mean); the markers are explained in the title
    legend: { top: 0, left: 0, type: 'scroll', data: es.map((e) => `mean ${e.speed_rpm} rpm`), textStyle: { color: '#14181f' } },
    title: { text: '▼ min   ● mean   ▲ max', right: 8, top: 2, textStyle: { fontSize: 12, fontWeight: 'normal', color: '#333b47' } },
    grid: { left: 56, right: 16, top: 40, bottom: 40 },
    tooltip: { trigger: 'axis' },
    xAxis: axis('load torque T_L [N m]', { nameGap: 26 }),
    yAxis: axis('position error [deg]', { nameGap: 40 }),
    series,
  };
}

// Delta I_m (MTPA trajectory) and Delta P_dcM (ME trajectory) against the reference per (speed,
// load), one bar series per configuration (Fig. 6.21).
export function deltaOption(analysis) {
  const es = analysis?.deltas?.entries || [];
  const keys = [...new Set(es.map((e) => `${e.speed_rpm}|${e.load_Nm}`))]
    .sort((a, b) => { const [sa, la] = a.split('|').map(Number); const [sb, lb] = b.split('|').map(Number); return sa - sb || la - lb; });
  const cfgs = [];
  for (const e of es) if (!cfgs.some((c) => sameCfg(c, e))) cfgs.push({ estimator: e.estimator, pwm: e.pwm });
  const cats = keys.map((k) => { const [s, l] = k.split('|'); return `${s} rpm\n${l} N m`; });
  const series = [];
  const bars = [];
  cfgs.forEach((cfg, k) => {
    const color = PALETTE[(k + 1) % PALETTE.length];
    const entry = (key) => es.find((x) => sameCfg(x, cfg) && `${x.speed_rpm}|${x.load_Nm}` === key);
    // a bar whose difference is not significant at 95 % is faded and hatched (data-significant="false" in the tooltip)
    const val = (f, o, uf, sf) => keys.map((key) => {
      const d = entry(key)?.[o];
      if (d?.[f] == null) return null;
      const sig = d[sf] ?? null;
      return { value: r2(d[f], 4), u: d[uf] ?? null, significant: sig,
        itemStyle: sig === false ? FADED : undefined };
    });
    series.push({ name: cfgLabel(cfg), type: 'bar', color, xAxisIndex: 0, yAxisIndex: 0, data: val('delta_im_A', 'mtpa', 'delta_im_u_A', 'delta_im_significant') });
    series.push({ name: cfgLabel(cfg), type: 'bar', color, xAxisIndex: 1, yAxisIndex: 1, data: val('delta_pdcm_W', 'me', 'delta_pdcm_u_W', 'delta_pdcm_significant') });
    const slot = { k, n: cfgs.length };
    const eb = (o, f, uf) => keys.map((key, i) => ({ x: i, y: entry(key)?.[o]?.[f], u: entry(key)?.[o]?.[uf] }));
    bars.push(errorBarSeries(`±2u ΔI_m ${cfgLabel(cfg)}`, '#14181f', eb('mtpa', 'delta_im_A', 'delta_im_u_A'), { slot }));
    bars.push(errorBarSeries(`±2u ΔP_dcM ${cfgLabel(cfg)}`, '#14181f', eb('me', 'delta_pdcm_W', 'delta_pdcm_u_W'), { slot, xAxisIndex: 1, yAxisIndex: 1 }));
  });
  series.push(...bars.filter(Boolean));
  const ref = analysis?.deltas?.reference;
  const anyInsignificant = series.some((x) => x.type === 'bar' && x.data.some((d) => d?.significant === false));
  return {
    legend: { top: 0, type: 'scroll', textStyle: { color: '#14181f' }, data: series.filter((x) => !x.errorBars).map((x) => x.name) },
    title: [ref ? { text: `vs ${cfgLabel(ref)}`, right: 8, top: 0, textStyle: { fontSize: 11, color: '#4a5361', fontWeight: 'normal' } } : undefined,
      { ...uNote(series, anyInsignificant ? ` · ${FADED_NOTE}` : ''), bottom: undefined, top: 18 }].filter(Boolean),
    tooltip: { trigger: 'axis', formatter: uTooltip((p) => (p.seriesIndex % 2 === 0 ? 'A' : 'W'), () => 4) },
    grid: [{ left: 60, right: 16, top: 48, height: '30%' }, { left: 60, right: 16, bottom: 44, height: '30%' }],
    xAxis: [{ type: 'category', data: cats, gridIndex: 0, axisLabel: { show: false } },
      { type: 'category', data: cats, gridIndex: 1, axisLabel: { color: '#333b47', fontSize: 10 } }],
    // bars start at zero
    yAxis: [axis('ΔI_m [A]', { gridIndex: 0, nameGap: 48, scale: false }), axis('ΔP_dcM [W]', { gridIndex: 1, nameGap: 48, scale: false })],
    series,
  };
}

// Histograms of one configuration (Figs. 6.16-6.19): up to four panels.
const HQ = [['pos_err_mean_deg', 'position error [deg]'], ['ld_err_pct', 'L_d error [%]'], ['lq_err_pct', 'L_q error [%]'], ['rs_err_pct', 'R_s error [%]']];
export function histOption(analysis, cfg) {
  const es = (analysis?.histograms?.entries || []).filter((e) => sameCfg(e, cfg));
  const present = HQ.filter(([q]) => es.some((e) => e.quantity === q));
  const n = present.length;
  const grid = [];
  const xAxis = [];
  const yAxis = [];
  const series = [];
  const title = [];
  present.forEach(([q, label], k) => {
    const e = es.find((x) => x.quantity === q);
    const col = k % 2;
    const row = Math.floor(k / 2);
    const rows = Math.ceil(n / 2);
    const w = n === 1 ? 88 : 40;
    grid.push({ left: `${7 + col * 50}%`, width: `${w}%`, top: `${8 + row * (90 / rows)}%`, height: `${90 / rows - 22}%` });
    xAxis.push({ type: 'category', gridIndex: k, data: e.bins.map((b) => r2(b.from, 2)), name: label, nameLocation: 'middle', nameGap: 22,
      axisLabel: { color: '#333b47', fontSize: 10 }, nameTextStyle: { color: '#333b47', fontWeight: 600 } });
    yAxis.push(axis('', { gridIndex: k, minInterval: 1, scale: false }));
    series.push({ type: 'bar', name: label, xAxisIndex: k, yAxisIndex: k, barCategoryGap: '5%', color: PALETTE[k], data: e.bins.map((b) => b.count) });
    title.push({ text: `n=${e.count}, mean ${r2(e.mean, 2)}`, left: `${7 + col * 50}%`, top: `${1 + row * (90 / rows)}%`, textStyle: { fontSize: 11, fontWeight: 'normal', color: '#4a5361' } });
  });
  return { grid, xAxis, yAxis, series, title, tooltip: { trigger: 'axis' } };
}
