// Efficiency contour map of the Results view (issue 25): the analysis' interpolated efficiency
// field (efficiency_contours, computed once by the daemon, docs/analysis.md) as a smooth heat map
// over speed x load, with the iso-efficiency lines drawn and labelled with their level in %.
import { axis } from '../charts.js';

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
  if (!e) return { option: { series: [] }, segments: 0, levels: 0 };
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
  const vals = cells.map((c) => c[4]);
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
      ? `${Math.round((p.value[0] + p.value[2]) / 2)} rpm, ${((p.value[1] + p.value[3]) / 2).toFixed(2)} N m<br>η ≈ ${p.value[4]} %`
      : `iso-efficiency η = ${pct(p.value[p.value.length - 1])}`) },
    grid: { left: 64, right: 80, top: 24, bottom: 40 },
    xAxis: axis('speed [rpm]', { nameGap: 26, min: e.speed_rpm[0], max: e.speed_rpm.at(-1), scale: false }),
    yAxis: axis('load torque T_L [N m]', { nameGap: 40, min: e.load_Nm[0], max: e.load_Nm.at(-1), scale: false }),
    visualMap: { seriesIndex: 0, dimension: 4, min: vals.length ? Math.floor(Math.min(...vals)) : 0, max: vals.length ? Math.ceil(Math.max(...vals)) : 100,
      calculable: true, orient: 'vertical', right: 4, top: 'middle', itemHeight: 160, text: ['η %', ''], textStyle: { color: '#14181f' },
      inRange: { color: ['#313695', '#4575b4', '#74add1', '#abd9e9', '#fee090', '#fdae61', '#f46d43', '#a50026'] } },
    series: [
      { name: 'efficiency field', type: 'custom', renderItem: rect, data: cells, encode: { x: [0, 2], y: [1, 3] } },
      { name: 'iso-efficiency lines', type: 'custom', renderItem: seg, data: segs, encode: { x: [0, 2], y: [1, 3] }, z: 3 },
      { name: 'levels', type: 'scatter', data: labels, symbolSize: 1, z: 4,
        label: { show: true, formatter: (p) => p.name, color: '#000', fontWeight: 700, textBorderColor: '#fff', textBorderWidth: 3 } },
    ],
  };
  return { option, segments: segs.length, levels: labels.length };
}

// Draws the contour map into a ChartCard; data-iso-segments / data-iso-levels say what was drawn.
export function drawContours(card, analysis, cfg, label) {
  const { option, segments, levels } = contourOption(analysis, cfg);
  card.set(option, { empty: 'needs efficiency at two speeds and two loads at least' });
  card.h.textContent = `Efficiency contours (interpolated, iso-η lines), ${label}`;
  card.card.dataset.isoSegments = String(segments);
  card.card.dataset.isoLevels = String(levels);
}
