// Numeric tables of the Results view: the MTPA and ME optima per configuration x speed x load
// (each value with its standard uncertainty u, k = 1, and the ME - MTPA difference with whether it
// is significant at 95 %), and the efficiency per load x speed of the chosen configuration with
// its u, each with a "Copy CSV" button. The values are the analysis document's (GET /api/sweeps/{id}/analysis), printed at a
// fixed precision; the CSV carries them unrounded.
import { saveBlob } from '../api.js';
import { analysisConfigs } from '../analysis_configs.js';
import { cfgLabel, sameCfg } from './plots.js';
import { escapeHtml } from './live.js';
import { fmtU, known } from '../errorbars.js';

// A cell: {v: the value for the CSV, t: the text shown}.
export const fmt = (v, d) => (v == null || !Number.isFinite(v) ? '–' : v.toFixed(d));
export const numCell = (v, d) => ({ v: v == null || !Number.isFinite(v) ? '' : v, t: fmt(v, d) });
export const textCell = (s) => ({ v: s, t: s });
// A standard uncertainty (k = 1), two significant digits; scale: e.g. 100 for %.
export const uCell = (u, scale = 1) => (known(u) ? { v: u * scale, t: fmtU(u * scale) } : { v: '', t: '–' });
// Significant at 95 %: true, false, or unknown (null: never a false "significant").
export const sigCell = (s) => textCell(s === true ? 'yes' : s === false ? 'no' : '–');
const pct = (v) => (v == null ? null : v * 100);
const note = (o) => (o ? [o.at_edge ? 'at edge' : '', o.refined ? 'refined' : ''].filter(Boolean).join(', ') : '');

const csvField = (v) => (/[",\n]/.test(String(v)) ? `"${String(v).replace(/"/g, '""')}"` : String(v));
export function tableCsv(model) {
  return [model.head.map(csvField).join(','), ...model.rows.map((r) => r.map((c) => csvField(c.v)).join(','))].join('\n') + '\n';
}

// model: {head: [text], rows: [[cell]], rowHead: number of leading columns that are row headers}
export function tableHtml(model) {
  const rh = model.rowHead ?? 1;
  const head = `<thead><tr>${model.head.map((h) => `<th scope="col">${escapeHtml(h)}</th>`).join('')}</tr></thead>`;
  const body = model.rows.map((r) => `<tr>${r.map((c, k) => (k < rh ? `<th scope="row">${escapeHtml(c.t)}</th>`
    : `<td${typeof c.v === 'number' ? ' class="num"' : ''}>${escapeHtml(c.t)}</td>`)).join('')}</tr>`).join('');
  return head + `<tbody>${body || `<tr><td colspan="${model.head.length}" class="muted">no data</td></tr>`}</tbody>`;
}

// A titled table with its "Copy CSV" button, appended to parent; returns {set(model, caption)}.
export function tableBlock(parent, id, title) {
  const sec = document.createElement('section');
  sec.className = 'table-block';
  sec.innerHTML = `<header><h3 id="${id}-h">${escapeHtml(title)}</h3>
    <button type="button" class="small" id="${id}-copy" aria-describedby="${id}-h">Copy CSV</button>
    <span class="muted" id="${id}-status" aria-live="polite"></span></header>
    <div class="table-wrap"><table class="table numeric" id="${id}" aria-labelledby="${id}-h"></table></div>`;
  parent.append(sec);
  let model = { head: [], rows: [] };
  const status = sec.querySelector(`#${id}-status`);
  sec.querySelector(`#${id}-copy`).addEventListener('click', async () => {
    const csv = tableCsv(model);
    try {
      await navigator.clipboard.writeText(csv);
      status.textContent = `copied ${model.rows.length} rows`;
    } catch {
      saveBlob(new Blob([csv], { type: 'text/csv' }), `${id}.csv`); // no clipboard (plain http): a file
      status.textContent = `saved ${id}.csv`;
    }
  });
  return {
    h: sec.querySelector('h3'),
    set(m, heading) {
      model = m;
      if (heading) this.h.textContent = heading;
      sec.querySelector('table').innerHTML = tableHtml(m);
      status.textContent = '';
    },
  };
}

// MTPA and ME optima of every configuration, speed and load.
export function optimaModel(analysis) {
  const order = analysisConfigs(analysis);
  const idx = (c) => order.findIndex((o) => sameCfg(o, c));
  const es = (analysis?.curves?.entries || []).slice()
    .sort((a, b) => idx(a) - idx(b) || a.speed_rpm - b.speed_rpm || a.load_Nm - b.load_Nm);
  // every value followed by its standard uncertainty u (k = 1)
  const opt = (o, uAngle) => [numCell(o?.angle_deg, 2), uCell(uAngle), numCell(o?.im_A, 3), uCell(o?.im_u_A), numCell(o?.pdcm_W, 1), uCell(o?.pdcm_u_W),
    numCell(pct(o?.efficiency), 1), uCell(o?.efficiency_u, 100), textCell(note(o))];
  const head = (t) => [`${t} angle [deg]`, `${t} angle ±u [deg]`, `${t} I_m [A]`, `${t} I_m ±u [A]`, `${t} P_dcM [W]`, `${t} P_dcM ±u [W]`,
    `${t} η [%]`, `${t} η ±u [%]`, `${t} note`];
  return {
    head: ['configuration', 'speed [rpm]', 'load [N m]', ...head('MTPA'), ...head('ME'),
      'ME − MTPA [deg]', 'ME − MTPA ±u [deg]', 'ME − MTPA significant at 95 %'],
    rowHead: 3,
    rows: es.map((e) => [textCell(cfgLabel(e)), numCell(e.speed_rpm, 0), numCell(e.load_Nm, 2), ...opt(e.mtpa, e.mtpa_angle_u_deg), ...opt(e.me, e.me_angle_u_deg),
      numCell(e.me_minus_mtpa_deg, 2), uCell(e.me_minus_mtpa_u_deg), sigCell(e.me_minus_mtpa_significant)]),
  };
}

// Efficiency at the ME angle of one configuration: rows load, columns speed.
export function efficiencyModel(analysis, cfg) {
  const e = (analysis?.efficiency_map?.entries || []).find((x) => sameCfg(x, cfg));
  if (!e) return { head: ['load [N m]'], rows: [] };
  return {
    head: ['load [N m]', ...e.speeds_rpm.flatMap((s) => [`η [%] at ${s} rpm`, `±u [%] at ${s} rpm`])],
    rows: e.loads_Nm.map((l, j) => [numCell(l, 2), ...e.speeds_rpm.flatMap((s, i) => [numCell(pct(e.efficiency[i]?.[j]), 1), uCell(e.efficiency_u?.[i]?.[j], 100)])]),
  };
}

export class ResultTables {
  constructor(panel) {
    this.optima = tableBlock(panel, 'r-optima', 'MTPA and ME optima per configuration, speed and load');
    this.eff = tableBlock(panel, 'r-eff', 'Efficiency η = P_m / P_dcM at the ME angle');
  }

  render(analysis, cfg) {
    this.optima.set(optimaModel(analysis));
    this.eff.set(efficiencyModel(analysis, cfg), `Efficiency η = P_m / P_dcM at the ME angle, ${cfgLabel(cfg)} (rows load, columns speed)`);
  }
}
