// The one colour scale of every efficiency map (the Results and progress map, the contour map and
// the HTML report, app/report/svg_plot.cpp): the report's viridis-like ramp, linear between its
// five stops, over one range per configuration, the lowest to the highest measured efficiency of
// its map cells (the interpolated field lies between them). Speed on x, torque on y everywhere.

// Same stops as the report's colour(t): {68,1,84} {59,82,139} {33,145,140} {94,201,98} {253,231,37}.
export const ETA_COLOURS = ['#440154', '#3b528b', '#21918c', '#5ec962', '#fde725'];

// [lo, hi] of the measured map cells of one efficiency_map entry, in % (null without a cell).
export function etaRangePct(entry) {
  const vals = (entry?.efficiency || []).flat().filter((v) => v != null && Number.isFinite(v)).map((v) => v * 100);
  if (!vals.length) return null;
  let lo = Math.min(...vals), hi = Math.max(...vals);
  if (hi - lo < 1e-10) { lo -= 50; hi += 50; } // as the report's Range::settle (0.5 of a fraction)
  return [lo, hi];
}

// The ECharts visualMap of an efficiency map over `range` (in %), on value dimension `dimension`.
export function etaVisualMap(range, dimension, extra = {}) {
  const [lo, hi] = range || [0, 100];
  return {
    dimension, min: lo, max: hi, precision: 1, calculable: true, orient: 'vertical', right: 4, top: 'middle', itemHeight: 160,
    text: ['η %', ''], textStyle: { color: '#14181f' }, inRange: { color: ETA_COLOURS }, ...extra,
  };
}
