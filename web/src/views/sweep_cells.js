// The per-point status cells of a sweep's progress: one cell per point, a grid sweep's in plan
// order, an adaptive sweep's in one row per curve (speed x load x configuration) with the points
// as the search measures them (no holes for evaluations it never needed). A point the sweep
// faulted or was aborted at says so (never "pending"). Keyboard: the cells are one tab stop
// (roving tabindex); arrows move, Home/End jump, and the focused cell's details go to an
// aria-live line (the mouse gets the same text as a tooltip).
const ACTIVE = ['running', 'pausing', 'paused', 'stopping'];

function pointText(p) {
  return `#${p.point_index} ${p.speed_rpm} rpm, ${p.load_Nm} N m, ${p.angle_deg}°, ${p.estimator}/${p.pwm}: I_m ${p.im_A?.toFixed(3)} A, `
    + `P_dcM ${p.pdcm_W?.toFixed(1)} W, η ${(100 * p.efficiency).toFixed(1)} %${p.fault ? `, fault ${p.fault}` : ''}`
    + `${p.unstable ? ', unstable' : ''}${p.voltage_limited ? ', voltage limited' : ''}`;
}
const pointClass = (p) => (p.fault ? 'c bad' : p.unstable || p.voltage_limited ? 'c warn' : 'c done');

export class ProgressCells {
  constructor(host, detail) {
    this.host = host;
    this.detail = detail;
    this.focusKey = null;
    host.setAttribute('role', 'group');
    host.addEventListener('keydown', (e) => this.key(e));
    host.addEventListener('focusin', (e) => { if (e.target.classList.contains('c')) this.focusCell(e.target, false); });
  }

  // What the sweep ended at, for the first point it did not measure.
  static endCell(state, error, where) {
    if (state === 'faulted') return { cls: 'c bad ended', title: `${where}: fault${error ? ` (${error})` : ''}` };
    if (state === 'aborted') return { cls: 'c aborted', title: `${where}: aborted${error ? ` (${error})` : ''}` };
    return null;
  }

  // Descriptors [{key, cls, title, row}] for the sweep as it stands.
  model({ state, error, points, total, expanded, groups, maxEvaluations }) {
    const active = ACTIVE.includes(state) && state !== 'paused';
    const out = [];
    if (groups) {
      const byGroup = new Map();
      for (const p of points) {
        const g = Math.floor(p.point_index / maxEvaluations);
        if (!byGroup.has(g)) byGroup.set(g, []);
        byGroup.get(g).push(p);
      }
      // The sweep's next point goes after the last one measured (whether that curve's search
      // needs it is not known before it comes); a curve not reached yet is one pending cell.
      const last = points.length ? Math.max(...byGroup.keys()) : (groups[0]?.group ?? 0);
      for (const g of groups) {
        const row = `${g.speed_rpm} rpm · ${g.load_Nm} N m · ${g.estimator}/${g.pwm}`;
        const got = (byGroup.get(g.group) || []).sort((a, b) => a.point_index - b.point_index);
        for (const p of got) out.push({ key: `p${p.point_index}`, cls: pointClass(p), title: pointText(p), row });
        if (g.group === last) {
          const where = `${row}, search point ${got.length + 1}`;
          const end = ProgressCells.endCell(state, error, where);
          if (end) out.push({ key: `g${g.group}n`, ...end, row });
          else if (active) out.push({ key: `g${g.group}n`, cls: 'c active', title: `${where}: measuring (or the next curve's first)`, row });
        } else if (!got.length && g.group > last && state !== 'completed') {
          out.push({ key: `g${g.group}`, cls: 'c pending', title: `${row}: curve not measured yet`, row });
        }
      }
      return out;
    }
    const byIndex = new Map(points.map((p) => [p.point_index, p]));
    const n = Math.min(total || 0, 5000);
    let firstMissing = -1;
    for (let i = 0; i < n; i++) if (!byIndex.has(i)) { firstMissing = i; break; }
    for (let i = 0; i < n; i++) {
      const p = byIndex.get(i);
      const e = expanded?.[i];
      const where = e ? `#${i} ${e.speed_rpm} rpm, ${e.load_Nm} N m, ${e.angle_deg}°, ${e.estimator}/${e.pwm}` : `#${i}`;
      if (p) { out.push({ key: `p${i}`, cls: pointClass(p), title: pointText(p) }); continue; }
      const end = i === firstMissing ? ProgressCells.endCell(state, error, where) : null;
      if (end) out.push({ key: `p${i}`, ...end });
      else if (i === firstMissing && active) out.push({ key: `p${i}`, cls: 'c active', title: `${where}: measuring` });
      else out.push({ key: `p${i}`, cls: 'c pending', title: `${where}: pending` });
    }
    return out;
  }

  render(sweep) {
    if (sweep.id !== this.id) { this.id = sweep.id; this.focusKey = null; this.detail.textContent = ''; }
    const cells = this.model(sweep);
    const shape = cells.map((c) => `${c.key}|${c.row || ''}`).join(',');
    const hadFocus = this.host.contains(document.activeElement);
    if (shape !== this.shape) {
      this.shape = shape;
      let html = '';
      let row = null;
      for (const c of cells) {
        if (c.row !== undefined && c.row !== row) {
          if (row !== null) html += '</div>';
          row = c.row;
          html += `<div class="cellrow" role="group" aria-label="${row}"><span class="rowlbl" aria-hidden="true">${row}</span>`;
        }
        html += `<span class="c" data-key="${c.key}" tabindex="-1" role="img"></span>`;
      }
      if (row !== null) html += '</div>';
      this.host.innerHTML = html;
      this.host.classList.toggle('by-curve', cells.some((c) => c.row !== undefined));
    }
    const els = this.els();
    cells.forEach((c, i) => {
      const el = els[i];
      if (el.className !== c.cls) el.className = c.cls;
      el.title = c.title;
      el.setAttribute('aria-label', c.title);
    });
    this.host.dataset.done = String(sweep.points.length);
    this.host.dataset.cells = String(cells.length);
    // One tab stop: the focused cell's, else the first.
    const keep = els.find((e) => e.dataset.key === this.focusKey) || els[0];
    for (const e of els) e.tabIndex = e === keep ? 0 : -1;
    if (hadFocus && keep && document.activeElement !== keep) keep.focus();
    if (keep && keep.dataset.key === this.focusKey) this.detail.textContent = keep.title;
  }

  els() { return [...this.host.querySelectorAll('.c')]; }

  focusCell(el, move = true) {
    for (const e of this.els()) e.tabIndex = e === el ? 0 : -1;
    this.focusKey = el.dataset.key;
    this.detail.textContent = el.title;
    if (move) el.focus();
  }

  key(e) {
    const els = this.els();
    const i = els.indexOf(document.activeElement);
    if (i < 0) return;
    const cur = els[i];
    let to = null;
    if (e.key === 'ArrowRight') to = els[i + 1];
    else if (e.key === 'ArrowLeft') to = els[i - 1];
    else if (e.key === 'Home') to = els[0];
    else if (e.key === 'End') to = els[els.length - 1];
    else if (e.key === 'ArrowDown' || e.key === 'ArrowUp') {
      // The nearest cell on the next (previous) visual line: the grid wraps, the curves are rows.
      const down = e.key === 'ArrowDown';
      const r = cur.getBoundingClientRect();
      let best = null, bestLine = null, bestDx = Infinity;
      for (const el of els) {
        const q = el.getBoundingClientRect();
        const dy = q.top - r.top;
        if (down ? dy <= 1 : dy >= -1) continue;
        if (bestLine !== null && (down ? q.top > bestLine + 1 : q.top < bestLine - 1)) continue;
        if (bestLine === null || (down ? q.top < bestLine - 1 : q.top > bestLine + 1)) { bestLine = q.top; bestDx = Infinity; }
        const dx = Math.abs(q.left - r.left);
        if (dx < bestDx) { bestDx = dx; best = el; }
      }
      to = best;
    } else return;
    e.preventDefault();
    if (to) this.focusCell(to);
  }
}
