// The Live view while a sweep owns the bench: the readout's sweep line ("sweep #2 running,
// point 85/665") and the point's configuration, the manual controls disabled with the reason in
// their title, and the feed of the last ~10 measured points (newest first: η, I_m, P_dcM with
// their standard uncertainty where the point has one, settle time, gate), read from the sweep's
// stored points when its count of stored points changes.
import { api } from '../api.js';
import { fmtU, known } from '../errorbars.js';
import { sig } from '../scope.js';

const ACTIVE = ['running', 'pausing', 'paused', 'stopping'];
// Efficiency in % everywhere on the page (a fraction in the record, docs/record.md).
const pct = (v) => (v == null || !Number.isFinite(v) ? v : v * 100);
const FEED_N = 10;
const $ = (s) => document.querySelector(s);
// The manual controls a sweep's bench refuses (the daemon answers sweep_running).
const MANUAL = ['#btn-enable', '#btn-disable', '#setpoints-form button[type=submit]', '#setpoints-form input',
  '#mode-form button[type=submit]', '#mode-form select'];

export const sweepActive = (st) => !!(st?.sweep && ACTIVE.includes(st.sweep.state));

// Readout rows for the sweep that runs (none without one).
export function sweepRows(st) {
  if (!sweepActive(st)) return [];
  const sw = st.sweep;
  const n = Math.min(sw.total, sw.done + (sw.state === 'running' || sw.state === 'pausing' ? 1 : 0));
  const rows = [['state', `sweep #${sw.id} ${sw.state}, point ${Math.max(n, sw.done)}/${sw.total}`]];
  const p = sw.point;
  if (p) rows.push(['point', `${sig(p.speed_rpm)} rpm, ${sig(p.load_Nm)} N m, ${sig(p.angle_deg)}°, ${p.estimator}/${p.pwm}`]);
  return rows;
}

// "0.7043 ± 0.0085" with the combined u (k = 1) and, in the title, its point-to-point part (what a
// comparison with the curve's neighbours carries, docs/uncertainty.md); the bare value without u.
function withU(value, digits, u, uRepeat, unit) {
  if (value == null) return '–';
  if (!known(u)) return `${sig(value, digits)}${unit}`;
  const title = `standard uncertainty (k = 1): ${fmtU(u)}${unit}`
    + (known(uRepeat) ? `, point to point ${fmtU(uRepeat)}${unit}` : '');
  return `<span class="u" title="${title}" data-u="${u}">${sig(value, digits)} ± ${fmtU(u)}${unit}</span>`;
}

export class SweepFeed {
  constructor() {
    this.list = $('#live-points');
    this.sweepId = null;
    this.done = -1;
    this.busy = false;
  }

  // On every status and sweep message: the controls, and the feed when a point was stored.
  update(st) {
    const active = sweepActive(st);
    const why = active ? `sweep #${st.sweep.id} drives the bench: pause or abort it in the Sweep view first` : '';
    for (const sel of MANUAL) {
      for (const el of document.querySelectorAll(sel)) {
        if (active) { el.disabled = true; el.title = why; el.dataset.sweepDisabled = '1'; }
        else if (el.dataset.sweepDisabled) { el.disabled = false; el.title = ''; delete el.dataset.sweepDisabled; }
      }
    }
    const sw = st?.sweep;
    if (!sw || sw.id == null) return;
    if (sw.id !== this.sweepId) { this.sweepId = sw.id; this.done = -1; this.rows = []; }
    if (sw.done !== this.done) this.fetch(sw.id, sw.done);
  }

  async fetch(id, done) {
    if (this.busy) { this.again = [id, done]; return; }
    this.busy = true;
    try {
      const pts = await api('GET', `/api/sweeps/${id}/points?offset=${Math.max(0, done - FEED_N)}&limit=${FEED_N}`, undefined, { quiet401: true });
      if (id === this.sweepId) { this.done = done; this.render(Array.isArray(pts) ? pts : []); }
    } catch { /* offline: the next status retries */ } finally {
      this.busy = false;
      if (this.again) { const [i, d] = this.again; this.again = null; if (d !== this.done) this.fetch(i, d); }
    }
  }

  render(points) {
    const rows = points.slice().sort((a, b) => b.point_index - a.point_index);
    $('#live-points-head').hidden = rows.length === 0;
    this.list.innerHTML = rows.map((p) => {
      const gate = p.fault ? `fault ${p.fault}` : p.unstable ? 'unstable' : 'settled';
      return `<li data-eta="${p.efficiency ?? ''}" data-index="${p.point_index}"><b>#${p.point_index + 1}</b> `
        + `${sig(p.speed_rpm)} rpm ${sig(p.load_Nm)} N m ${sig(p.angle_deg)}°: `
        + `η ${withU(pct(p.efficiency), 3, pct(p.efficiency_u), pct(p.efficiency_u_repeat), ' %')}, `
        + `I_m ${withU(p.im_A, 3, p.im_u_A, p.im_u_repeat_A, ' A')}, P_dcM ${withU(p.pdcm_W, 4, p.pdcm_u_W, p.pdcm_u_repeat_W, ' W')}, `
        + `settle ${sig(p.settle_s, 3)} s, <span class="gate ${p.unstable || p.fault ? 'bad' : 'ok'}">${gate}</span></li>`;
    }).join('');
  }
}
