// Error bars and uncertainty text for the result charts (issue 26, docs/uncertainty.md): a value
// with its combined standard uncertainty u (k = 1) is drawn as a bar of +/- U = 2u (about 95 %),
// and told as "value ± u unit (k=1)". One ECharts custom series per set of bars; each datum is
// [x, y - 2u, y + 2u, u, y] so a test can read the half-length back from the option.

export const K = 2; // coverage factor of the drawn bars (about 95 % for a normal distribution)
export const BARS_NOTE = 'bars: ±2u, 95 %';
export const NO_U_NOTE = 'no uncertainty stored';

export const known = (u) => typeof u === 'number' && Number.isFinite(u) && u >= 0;

// u with two significant digits ("0.013").
export function fmtU(u) {
  if (!known(u)) return '–';
  if (u === 0) return '0';
  const d = Math.max(0, 1 - Math.floor(Math.log10(u)));
  return u.toFixed(Math.min(d, 8));
}

// "261.83 ± 0.013 W (k=1)", or "261.83 W" without a u.
export function pm(v, u, unit = '', digits = 2) {
  if (v == null || !Number.isFinite(v)) return '–';
  const sp = unit === '°' ? unit : unit ? ` ${unit}` : '';
  return known(u) ? `${v.toFixed(digits)} ± ${fmtU(u)}${sp} (k=1)` : `${v.toFixed(digits)}${sp}`;
}

// The look of a bar whose difference is not significant at 95 %: faded and hatched.
export const FADED = { opacity: 0.35, decal: { symbol: 'rect', dashArrayX: [1, 0], dashArrayY: [2, 4], rotation: Math.PI / 4, color: 'rgba(0,0,0,0.45)' } };
export const FADED_NOTE = 'faded, hatched: not significant at 95 %';

// Significance text of a difference: true, false or null (unknown: never a false "significant").
export const sigText = (s) => (s === true ? 'significant at 95 %' : s === false ? 'not significant at 95 %' : 'unknown');

// items: [{x, y, u}] (x a number, or a category index); those without y or u are skipped.
// slot: {k, n} places the bar on the k-th of n bars of a category (ECharts' default bar layout).
export function errorBarSeries(name, color, items, { xAxisIndex = 0, yAxisIndex = 0, slot = null } = {}) {
  const data = items.filter((i) => i.y != null && Number.isFinite(i.y) && known(i.u))
    .map((i) => [i.x, i.y - K * i.u, i.y + K * i.u, i.u, i.y]);
  if (!data.length) return null;
  const renderItem = (params, api) => {
    const lo = api.coord([api.value(0), api.value(1)]);
    const hi = api.coord([api.value(0), api.value(2)]);
    let x = lo[0];
    if (slot) {
      const band = api.size([1, 0])[0];
      const w = (band * 0.8) / (slot.n + (slot.n - 1) * 0.3); // barCategoryGap 20 %, barGap 30 %
      x += -band * 0.4 + slot.k * w * 1.3 + w / 2;
    }
    const cap = 4;
    const style = { stroke: color, lineWidth: 1.5 };
    return { type: 'group', children: [
      { type: 'line', shape: { x1: x, y1: lo[1], x2: x, y2: hi[1] }, style },
      { type: 'line', shape: { x1: x - cap, y1: lo[1], x2: x + cap, y2: lo[1] }, style },
      { type: 'line', shape: { x1: x - cap, y1: hi[1], x2: x + cap, y2: hi[1] }, style },
    ] };
  };
  return { name, type: 'custom', errorBars: true, renderItem, data, xAxisIndex, yAxisIndex, z: 5, silent: true,
    encode: { x: 0, y: [1, 2] }, tooltip: { show: false } };
}

// Only the bars of an option's series, or only the other series.
export const isBars = (s) => !!s?.errorBars;
export const withoutBars = (series) => series.filter((s) => !isBars(s));
