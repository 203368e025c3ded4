// The Live view's scope controls: the time span shown (10 s .. 15 min), freeze (the charts stop
// scrolling while the buffer keeps filling; unfreezing catches up), two cursors (click a chart:
// A, then B; Δt and every channel's value at both), the channel chooser (which charts are shown,
// remembered in localStorage), tooltips with units and 4 significant digits, and "CSV" of the
// buffer (one row per sample time, units in the header's names).
import { saveBlob } from './api.js';

export const SPANS = [[10, '10 s'], [60, '60 s'], [300, '5 min'], [900, '15 min']];
const HIDDEN_KEY = 'synbench.live.hidden';
const SPAN_KEY = 'synbench.live.span_s';

// A number with `sig` significant digits at most, no exponent for bench-sized values.
export function sig(v, digits = 4) {
  if (v == null || !Number.isFinite(v)) return '–';
  if (v === 0) return '0';
  const a = Math.abs(v);
  const decimals = Math.max(0, Math.min(6, digits - 1 - Math.floor(Math.log10(a))));
  return Number(v.toFixed(decimals)).toString();
}

// Bench time: "42.35 s", "12:05.3"
export function timeText(t) {
  if (!Number.isFinite(t)) return '–';
  const neg = t < 0 ? '−' : '';
  const a = Math.abs(t);
  if (a < 600) return `${neg}${sig(a, a < 10 ? 3 : 4)} s`;
  const m = Math.floor(a / 60);
  return `${neg}${m}:${(a - 60 * m).toFixed(1).padStart(4, '0')}`;
}

// The ECharts axis tooltip: time, then each series with its unit.
export function tooltipFormatter(unit) {
  return (params) => {
    const ps = [].concat(params);
    if (!ps.length) return '';
    const t = Array.isArray(ps[0].value) ? ps[0].value[0] : ps[0].axisValue;
    const rows = ps.filter((p) => Array.isArray(p.value) && p.value[1] != null)
      .map((p) => `${p.marker}${p.seriesName}: <b>${sig(p.value[1])} ${unit}</b>`);
    return [`t = ${timeText(t)}`, ...rows].join('<br>');
  };
}

// The sample at or just before t (binary search on t_s).
export function sampleAt(buf, t) {
  let lo = 0;
  let hi = buf.length - 1;
  if (hi < 0 || t < buf[0].t_s) return null;
  while (lo < hi) {
    const mid = (lo + hi + 1) >> 1;
    if (buf[mid].t_s <= t) lo = mid; else hi = mid - 1;
  }
  return buf[lo];
}

export class Scope {
  // charts: [{id, title, unit, series: [[key, name]]}]; onChange: redraw everything
  constructor(root, charts, { onChange, samples, csvColumns }) {
    this.root = root;
    this.charts = charts;
    this.onChange = onChange;
    this.samples = samples;        // () => the live buffer
    this.csvColumns = csvColumns;  // [[key, header]]
    this.frozen = false;
    this.cursors = [];             // up to two bench times
    this.hidden = new Set(readJson(HIDDEN_KEY, []));
    this.span_s = Number(localStorage.getItem(SPAN_KEY)) || 60;
    if (!SPANS.some(([s]) => s === this.span_s)) this.span_s = 60;
    this.build();
  }

  build() {
    const opts = SPANS.map(([s, l]) => `<option value="${s}"${s === this.span_s ? ' selected' : ''}>${l}</option>`).join('');
    const boxes = this.charts.map((c) => `<label><input type="checkbox" data-channel="${c.id}"${this.hidden.has(c.id) ? '' : ' checked'}> ${c.title}</label>`).join('');
    this.root.innerHTML = `
      <label>Span <select id="scope-span" aria-label="Time span shown">${opts}</select></label>
      <button type="button" id="scope-freeze" aria-pressed="false" title="Stop scrolling (the buffer keeps filling)">Freeze</button>
      <button type="button" id="scope-csv" title="The buffered telemetry as CSV">CSV</button>
      <button type="button" id="scope-clear-cursors" title="Remove the cursors">Clear cursors</button>
      <details class="scope-channels"><summary>Channels</summary><div id="scope-channels">${boxes}</div></details>
      <p class="scope-hint">Click a chart: cursor A, then B. Wheel or drag on a chart zooms.</p>`;
    this.root.querySelector('#scope-span').addEventListener('change', (e) => {
      this.span_s = Number(e.target.value);
      localStorage.setItem(SPAN_KEY, String(this.span_s));
      this.onChange();
    });
    this.root.querySelector('#scope-freeze').addEventListener('click', () => this.setFrozen(!this.frozen));
    this.root.querySelector('#scope-csv').addEventListener('click', () => this.saveCsv());
    this.root.querySelector('#scope-clear-cursors').addEventListener('click', () => { this.cursors = []; this.renderCursors(); this.onChange(); });
    this.root.querySelector('#scope-channels').addEventListener('change', (e) => {
      const id = e.target.dataset.channel;
      if (!id) return;
      if (e.target.checked) this.hidden.delete(id); else this.hidden.add(id);
      localStorage.setItem(HIDDEN_KEY, JSON.stringify([...this.hidden]));
      this.onChange();
    });
  }

  shown(id) { return !this.hidden.has(id); }

  setFrozen(on) {
    this.frozen = on;
    const b = this.root.querySelector('#scope-freeze');
    b.textContent = on ? 'Unfreeze' : 'Freeze';
    b.setAttribute('aria-pressed', String(on));
    this.onChange();
  }

  // A click on a chart at bench time t: A, then B, then A again.
  addCursor(t) {
    if (this.cursors.length >= 2) this.cursors = [];
    this.cursors.push(t);
    this.renderCursors();
    this.onChange();
  }

  renderCursors() {
    const el = document.querySelector('#scope-cursors'); // below the charts: it never moves them
    if (!this.cursors.length) { el.innerHTML = ''; return; }
    const buf = this.samples();
    const [a, b] = this.cursors;
    const sa = sampleAt(buf, a);
    const sb = b != null ? sampleAt(buf, b) : null;
    const head = b != null ? `A ${timeText(a)}, B ${timeText(b)}, Δt ${sig(b - a)} s` : `A ${timeText(a)} (click again for B)`;
    const rows = this.charts.filter((c) => this.shown(c.id)).flatMap((c) => c.series.map(([key, name]) => {
      const va = sa?.[key];
      const vb = sb?.[key];
      return `<tr><th scope="row">${c.title} ${name}</th><td>${sig(va)}</td>${b != null ? `<td>${sig(vb)}</td><td>${va != null && vb != null ? sig(vb - va) : '–'}</td>` : ''}<td>${c.unit}</td></tr>`;
    })).join('');
    el.innerHTML = `<p>${head}</p><table><thead><tr><th></th><th>A</th>${b != null ? '<th>B</th><th>B − A</th>' : ''}<th></th></tr></thead><tbody>${rows}</tbody></table>`;
  }

  // Cursor lines for a chart's first series.
  markLine() {
    if (!this.cursors.length) return { data: [] };
    return {
      silent: true, symbol: 'none', animation: false,
      label: { formatter: (p) => p.name, color: '#14181f' },
      lineStyle: { color: '#14181f', type: 'solid', width: 1 },
      data: this.cursors.map((t, i) => ({ name: i ? 'B' : 'A', xAxis: t })),
    };
  }

  csv() {
    const cols = this.csvColumns;
    const lines = [cols.map(([, h]) => h).join(',')];
    for (const s of this.samples()) {
      lines.push(cols.map(([k]) => {
        const v = s[k];
        return v == null || (typeof v === 'number' && !Number.isFinite(v)) ? '' : typeof v === 'number' ? String(Number(v.toPrecision(7))) : String(v);
      }).join(','));
    }
    return `${lines.join('\n')}\n`;
  }

  saveCsv() {
    saveBlob(new Blob([this.csv()], { type: 'text/csv' }), `synbench-live-${new Date().toISOString().replace(/[:.]/g, '-')}.csv`);
  }
}

function readJson(key, fallback) {
  try { const v = JSON.parse(localStorage.getItem(key)); return Array.isArray(v) ? v : fallback; } catch { return fallback; }
}
