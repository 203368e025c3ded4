// A chart card's PNG export that says what it is: the chart drawn again, off screen, with a title
// band on top (the figure, sweep #id and name, configuration, date) and saved as
// synbench-<sweep id>-<figure>-<configuration>-<YYYY-MM-DD>.png. The card on the page is left
// as it is. window.synbench.lastExport keeps the file name and the exported instance's titles
// (for the end-to-end tests).
import * as echarts from 'echarts/core';
import { saveBlob } from './api.js';

const BAND_PX = 62; // room for the title and its subtitle line

export const slug = (s) => String(s).replace(/[^A-Za-z0-9]+/g, '-').replace(/^-|-$/g, '').toLowerCase();

export function exportFileName({ sweepId, figure, config, date }) {
  return `synbench-${sweepId}-${slug(figure)}-${slug(config)}-${date}.png`;
}

// The date of a sweep as YYYY-MM-DD: when it finished, else when it was created, else today.
export function sweepDate(s) {
  const t = s?.finished_at || s?.created_at;
  return t && /^\d{4}-\d\d-\d\d/.test(t) ? t.slice(0, 10) : new Date().toISOString().slice(0, 10);
}

// Moves components positioned from the top down by the band; percentages of the old height
// become pixels so panels keep their size.
function shiftDown(comp, h) {
  const px = (v) => (typeof v === 'number' ? v + BAND_PX : typeof v === 'string' && v.endsWith('%') ? BAND_PX + (parseFloat(v) / 100) * h : v);
  return [].concat(comp ?? []).filter(Boolean).map((c) => {
    const o = { ...c };
    if (o.top !== undefined) o.top = px(o.top);
    else if (o.bottom === undefined) o.top = BAND_PX;
    if (typeof o.height === 'string' && o.height.endsWith('%')) o.height = (parseFloat(o.height) / 100) * h;
    return o;
  });
}

// card: a ChartCard with option (the last one set) and exportMeta() ->
// {title, subtitle, sweepId, figure, config, date}.
export function exportTitledPng(card) {
  const meta = card.exportMeta();
  const w = card.el.clientWidth || 800;
  const h = card.el.clientHeight || 300;
  const opt = card.option;
  const title = { text: meta.title, subtext: meta.subtitle, left: 10, top: 6, itemGap: 6,
    textStyle: { fontSize: 14, fontWeight: 700, color: '#14181f', width: w - 20, overflow: 'truncate' },
    subtextStyle: { fontSize: 12, color: '#333b47', width: w - 20, overflow: 'truncate' } };
  const option = { ...opt, grid: shiftDown(opt.grid, h), title: [title, ...shiftDown(opt.title, h)] };
  if (opt.legend) option.legend = shiftDown(opt.legend, h);
  const div = document.createElement('div');
  div.style.cssText = `position:fixed;left:-10000px;top:0;width:${w}px;height:${h + BAND_PX}px`;
  document.body.append(div);
  const inst = echarts.init(div, null, { renderer: 'canvas', width: w, height: h + BAND_PX });
  try {
    inst.setOption(option, { notMerge: true });
    const filename = exportFileName(meta);
    const titles = inst.getOption().title.map((t) => [t.text, t.subtext].filter(Boolean).join('\n'));
    const url = inst.getDataURL({ type: 'png', pixelRatio: 2, backgroundColor: '#ffffff' });
    if (window.synbench) window.synbench.lastExport = { filename, titles, width: w, height: h + BAND_PX };
    return fetch(url).then((r) => r.blob()).then((b) => saveBlob(b, filename));
  } finally {
    inst.dispose();
    div.remove();
  }
}
