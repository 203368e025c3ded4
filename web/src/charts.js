// ECharts, tree-shaken to what the dashboard draws, and the chart card: title, current value,
// PNG export (ECharts' getDataURL), an "no data yet" note, and data-points="N" (the number of
// finite data values drawn) for the end-to-end tests.
import * as echarts from 'echarts/core';
import { LineChart, HeatmapChart, BarChart, ScatterChart, CustomChart } from 'echarts/charts';
import {
  GridComponent, TooltipComponent, LegendComponent, VisualMapComponent, TitleComponent, DataZoomComponent,
  MarkLineComponent,
} from 'echarts/components';
import { CanvasRenderer } from 'echarts/renderers';
import { saveBlob } from './api.js';
import { exportTitledPng } from './export_png.js';

echarts.use([LineChart, HeatmapChart, BarChart, ScatterChart, CustomChart, GridComponent, TooltipComponent, LegendComponent,
  VisualMapComponent, TitleComponent, DataZoomComponent, MarkLineComponent, CanvasRenderer]);

// Okabe-Ito based palette: distinguishable with colour-blindness, dark enough on white.
export const PALETTE = ['#0b57d0', '#d55e00', '#009e73', '#cc79a7', '#7a5c00', '#56b4e9', '#6a3d9a', '#000000'];

const BASE = {
  animation: false,
  color: PALETTE,
  textStyle: { color: '#14181f', fontFamily: 'system-ui, sans-serif' },
  grid: { left: 56, right: 16, top: 28, bottom: 34, containLabel: false },
  tooltip: { trigger: 'axis', confine: true },
};

export function axis(name, extra = {}) {
  return {
    type: 'value', name, nameLocation: 'middle', nameGap: 36, scale: true,
    nameTextStyle: { color: '#333b47', fontWeight: 600 },
    axisLabel: { color: '#333b47' }, axisLine: { lineStyle: { color: '#5d6675' } },
    splitLine: { lineStyle: { color: '#e3e7ed' } },
    ...extra,
  };
}

function countData(option) {
  let n = 0;
  for (const s of [].concat(option.series || [])) {
    for (const d of s.data || []) {
      const v = Array.isArray(d) ? d[d.length - 1] : d && typeof d === 'object' ? (Array.isArray(d.value) ? d.value[d.value.length - 1] : d.value) : d;
      if (typeof v === 'number' && Number.isFinite(v)) n++;
    }
  }
  return n;
}

export class ChartCard {
  // card: an element with class chart-card; opts: {title, subtitle, valueLabel, png: filename base}
  constructor(card, { title, png = true }) {
    this.card = card;
    card.innerHTML = '';
    const head = document.createElement('header');
    this.h = document.createElement('h3');
    this.h.textContent = title;
    this.valueEl = document.createElement('span');
    this.valueEl.className = 'value';
    head.append(this.h, this.valueEl);
    if (png) {
      const b = document.createElement('button');
      b.type = 'button';
      b.className = 'small';
      b.textContent = 'PNG';
      b.title = `Save "${title}" as PNG`;
      b.setAttribute('aria-label', `Save ${title} as PNG`);
      b.addEventListener('click', () => this.savePng());
      head.append(b);
    }
    this.el = document.createElement('div');
    this.el.className = 'chart';
    this.el.setAttribute('role', 'img');
    this.el.setAttribute('aria-label', title);
    this.emptyEl = document.createElement('div');
    this.emptyEl.className = 'empty';
    this.emptyEl.textContent = 'no data yet';
    card.append(head, this.el, this.emptyEl);
    this.title = title;
    this.chart = null;
    card.dataset.points = '0';
  }

  ensure() {
    if (!this.chart) {
      this.chart = echarts.init(this.el, null, { renderer: 'canvas' });
      new ResizeObserver(() => this.chart && this.chart.resize()).observe(this.el);
    }
    return this.chart;
  }

  set(option, { empty = 'no data yet' } = {}) {
    const merged = { ...BASE, ...option };
    this.option = merged; // for the titled export and the keyboard point reader
    this.ensure().setOption(merged, { notMerge: true, lazyUpdate: true });
    const n = countData(merged);
    this.card.dataset.points = String(n);
    this.emptyEl.textContent = empty;
    this.emptyEl.hidden = n > 0;
  }

  // Cheap update of series data only (live charts).
  update(partial) {
    this.ensure().setOption(partial, { lazyUpdate: true });
    const n = countData(partial);
    this.card.dataset.points = String(n);
    this.emptyEl.hidden = n > 0;
  }

  value(text) { this.valueEl.textContent = text; }

  savePng() {
    if (!this.chart) return;
    if (this.exportMeta && this.option) return exportTitledPng(this); // Results: a titled figure
    const url = this.chart.getDataURL({ type: 'png', pixelRatio: 2, backgroundColor: '#ffffff' });
    fetch(url).then((r) => r.blob()).then((b) => saveBlob(b, `${this.title.replace(/[^A-Za-z0-9]+/g, '-').replace(/^-|-$/g, '').toLowerCase()}.png`));
  }
}

export { echarts };
