// Efficiency contour map of the Results view (issue 25): the analysis' interpolated efficiency
// field (efficiency_contours, computed once by the daemon, docs/analysis.md) as a smooth heat map
// over speed x load, with the iso-efficiency lines drawn and labelled with their level in %, the
// measured points it is interpolated from marked, in the one colour scale and range of every
// efficiency map (eta_scale.js), and a note when the field rests on few points.
import { axis } from '../charts.js';
import { etaRangePct, etaVisualMap } from '../eta_scale.js';

// Fewer measured speeds or loads than this: the field is one bilinear patch across the whole
// range, a guess between corners rather than a map, and the card says so.
export const FEW_PER_AXIS = 3;

const sameCfg = (a, b) => a && b && a.estimator === b.estimator && a.pwm === b.pwm;
const pct = (v) => `${Number((v * 100).toFixed(1))} %`;

// Cell edges of a field axis: halfway between neighbouring positions, the ends at the data.
function edges(v) {
  return v.map((x, i) => [i === 0 ? x : (v[i - 1] + x) / 2, i === v.length - 1 ? x : (x + v[i + 1]) / 2]);
}

// The ECharts option for one configuration, and how many iso-line segments and levels it draws.
export function contourOption(analysis, cfg) {
  const all = analysis?.efficiency_contours?.entries || [];
  const e = all.find((x) => sameCfg(x, cfg)) || all[0];
  if (!e) return { option: { series: [] }, segments: 0, levels: 0, measured: 0, note: '' };
  // The measured cells of the same configuration (efficiency_map: rows speed, columns load).
  const m = (analysis?.efficiency_map?.entries || []).find((x) => sameCfg(x, e));
  const measured = [];
  m?.speeds_rpm.forEach((sp, i) => m.loads_Nm.forEach((l, j) => {
    const v = m.efficiency[i]?.[j];
    if (v != null) measured.push({ value: [sp, l, Number((v * 100).toFixed(1))] });
  }));
  const nSpeeds = new Set(measured.map((p) => p.value[0])).size, nLoads = new Set(measured.map((p) => p.value[1])).size;
  const note = measured.length && (nSpeeds < FEW_PER_AXIS || nLoads < FEW_PER_AXIS)
    ? `interpolated from only ${measured.length} measured points\n(${nSpeeds} speeds x ${nLoads} loads): a guess between them` : '';
  const xs = edges(e.speed_rpm), ys = edges(e.load_Nm);
  const cells = [];
  e.efficiency.forEach((row, i) => row.forEach((v, j) => {
    if (v != null) cells.push([xs[j][0], ys[i][0], xs[j][1], ys[i][1], Number((v * 100).toFixed(2))]);
  }));
  const segs = [];
  const labels = [];
  for (const line of e.lines) {
    let best = null;
    for (const [[x0, y0], [x1, y1]] of line.segments) {
      segs.push([x0, y0, x1, y1, line.level]);
      const len = Math.hypot((x1 - x0) / (e.speed_rpm.at(-1) - e.speed_rpm[0] || 1), (y1 - y0) / (e.load_Nm.at(-1) - e.load_Nm[0] || 1));
      if (!best || len > best.len) best = { len, at: [(x0 + x1) / 2, (y0 + y1) / 2] };
    }
    if (best) labels.push({ value: [...best.at, line.level], name: pct(line.level) });
  }
  const rect = (params, api) => {
    const p0 = api.coord([api.value(0), api.value(1)]), p1 = api.coord([api.value(2), api.value(3)]);
    return { type: 'rect', shape: { x: p0[0], y: p1[1], width: p1[0] - p0[0] + 0.5, height: p0[1] - p1[1] + 0.5 },
      style: { fill: api.visual('color') } };
  };
  const seg = (params, api) => {
    const p0 = api.coord([api.value(0), api.value(1)]), p1 = api.coord([api.value(2), api.value(3)]);
    return { type: 'line', shape: { x1: p0[0], y1: p0[1], x2: p1[0], y2: p1[1] }, style: { stroke: '#111', lineWidth: 1.6 } };
  };
  const option = {
    tooltip: { trigger: 'item', formatter: (p) => (p.seriesIndex === 0
      ? `${Math.round((p.value[0] + p.value[2]) / 2)} rpm, ${((p.value[1] + p.value[3]) / 2).toFixed(2)} N m<br>η ≈ ${p.value[4]} % (interpolated)`
      : p.seriesName === 'measured points' ? `measured: ${p.value[0]} rpm, ${p.value[1]} N m<br>η = ${p.value[2]} %`
        : `iso-efficiency η = ${pct(p.value[p.value.length - 1])}`) },
    title: note ? { text: `○ measured points · ${note}`, left: 8, bottom: 0, textStyle: { fontSize: 11, fontWeight: 600, color: '#8a3b00', lineHeight: 14 } }
      : { text: '○ measured points', right: 8, bottom: 0, textStyle: { fontSize: 11, fontWeight: 'normal', color: '#4a5361' } },
    grid: { left: 64, right: 80, top: 24, bottom: note ? 66 : 40 },
    xAxis: axis('speed [rpm]', { nameGap: 26, min: e.speed_rpm[0], max: e.speed_rpm.at(-1), scale: false }),
    yAxis: axis('load torque T_L [N m]', { nameGap: 40, min: e.load_Nm[0], max: e.load_Nm.at(-1), scale: false }),
    // the map's range, from the measured cells (the bilinear field lies between them)
    visualMap: etaVisualMap(etaRangePct(m) || fieldRange(cells), 4, { seriesIndex: 0 }),
    series: [
      { name: 'efficiency field', type: 'custom', renderItem: rect, data: cells, encode: { x: [0, 2], y: [1, 3] } },
      { name: 'iso-efficiency lines', type: 'custom', renderItem: seg, data: segs, encode: { x: [0, 2], y: [1, 3] }, z: 3 },
      { name: 'levels', type: 'scatter', data: labels, symbolSize: 1, z: 4,
        label: { show: true, formatter: (p) => p.name, color: '#000', fontWeight: 700, textBorderColor: '#fff', textBorderWidth: 3 } },
      { name: 'measured points', type: 'scatter', data: measured, symbol: 'circle', symbolSize: 7, z: 5,
        itemStyle: { color: '#ffffff', borderColor: '#000000', borderWidth: 1.5 } },
    ],
  };
  return { option, segments: segs.length, levels: labels.length, measured: measured.length, note };
}

// Without the measured map (an older analysis): the field's own extremes.
function fieldRange(cells) {
  if (!cells.length) return null;
  const v = cells.map((c) => c[4]);
  return [Math.min(...v), Math.max(...v)];
}

// Draws the contour map into a ChartCard; data-iso-segments / data-iso-levels say what was drawn.
export function drawContours(card, analysis, cfg, label) {
  const { option, segments, levels, measured, note } = contourOption(analysis, cfg);
  card.set(option, { empty: 'needs efficiency at two speeds and two loads at least' });
  card.h.textContent = `Efficiency contours (interpolated, iso-η lines), ${label}`;
  card.card.dataset.isoSegments = String(segments);
  card.card.dataset.isoLevels = String(levels);
  card.card.dataset.measuredPoints = String(measured);
  card.card.dataset.fewPoints = note ? 'true' : 'false';
  card.card.dataset.note = note.replace('\n', ' ');
}
