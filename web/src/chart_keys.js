// Keyboard access to a chart card's points: the chart takes focus (Tab), the arrow keys move a
// highlighted point (Left/Right along a series, Up/Down between series, Home/End), and a line
// under the chart, read out by screen readers (aria-live), says the point's series and values,
// as the mouse tooltip does.

const num = (v) => (v == null || (typeof v === 'number' && !Number.isFinite(v)) ? '–' : String(v));

// What point `di` of series `si` of an ECharts option is, in words.
export function describePoint(option, si, di) {
  const s = option.series[si];
  const n = s.data.length;
  const d = s.data[di];
  const v = d && typeof d === 'object' && !Array.isArray(d) ? d.value : d;
  const xa = [].concat(option.xAxis ?? [])[s.xAxisIndex || 0] || {};
  const ya = [].concat(option.yAxis ?? [])[s.yAxisIndex || 0] || {};
  const at = (ax, k) => (ax.type === 'category' ? ax.data?.[k] : k);
  const xn = xa.name || 'x';
  const yn = ya.name || (s.type === 'bar' ? 'count' : 'y');
  let text;
  if (Array.isArray(v) && v.length >= 3) text = `${xn} ${num(at(xa, v[0]))}, ${yn} ${num(at(ya, v[1]))}: ${num(v[2])}`;
  else if (Array.isArray(v)) text = `${xn} ${num(v[0])}, ${yn} ${num(v[1])}`;
  else text = `${xn} ${num(String(at(xa, di)).replace(/\n/g, ' '))}, ${yn} ${num(v)}`;
  return `${s.name || `series ${si + 1}`}: ${text} (point ${di + 1} of ${n})`;
}

// card: a ChartCard (el, chart, option, card).
export function keyboardPoints(card) {
  const el = card.el;
  el.tabIndex = 0;
  el.setAttribute('role', 'group');
  el.setAttribute('aria-roledescription', 'chart');
  el.setAttribute('aria-label', `${card.title}: arrow keys read the points`);
  const out = document.createElement('p');
  out.className = 'point-readout';
  out.setAttribute('aria-live', 'polite');
  out.textContent = '';
  card.card.append(out);
  card.readout = out;
  let si = 0;
  let di = -1;
  el.addEventListener('keydown', (e) => {
    const series = card.option?.series || [];
    const filled = series.map((s, k) => ((s.data || []).length ? k : -1)).filter((k) => k >= 0);
    if (!filled.length || !card.chart) return;
    if (!filled.includes(si)) { si = filled[0]; di = -1; }
    const len = () => series[si].data.length;
    di = Math.min(di, len() - 1); // the option may have changed since the last key
    const pos = filled.indexOf(si);
    switch (e.key) {
      case 'ArrowRight': di = Math.min(di + 1, len() - 1); break;
      case 'ArrowLeft': di = Math.max(di - 1, 0); break;
      case 'ArrowDown': si = filled[Math.min(pos + 1, filled.length - 1)]; di = Math.min(Math.max(di, 0), len() - 1); break;
      case 'ArrowUp': si = filled[Math.max(pos - 1, 0)]; di = Math.min(Math.max(di, 0), len() - 1); break;
      case 'Home': di = 0; break;
      case 'End': di = len() - 1; break;
      default: return;
    }
    e.preventDefault();
    card.chart.dispatchAction({ type: 'downplay' });
    card.chart.dispatchAction({ type: 'highlight', seriesIndex: si, dataIndex: di });
    card.chart.dispatchAction({ type: 'showTip', seriesIndex: si, dataIndex: di });
    out.textContent = describePoint(card.option, si, di);
  });
  el.addEventListener('blur', () => { card.chart?.dispatchAction({ type: 'hideTip' }); card.chart?.dispatchAction({ type: 'downplay' }); });
}
