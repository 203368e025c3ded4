// History view: every sweep in the daemon's store, with the bench that measured it (a lab's
// benches may share one store, docs/database.md), a filter by bench, links to its progress and
// results, and two ticked runs, of one bench or of two, opened side by side in the Results view's
// comparison (#/results/A/vs/B).
import { benchLabel } from '../bench_label.js';
import { escapeHtml } from './live.js';

const $ = (s) => document.querySelector(s);
const when = (t) => (t ? new Date(t.replace(' ', 'T')).toLocaleString() : '–');

export class HistoryView {
  constructor(app) {
    this.app = app;
    this.ticked = [];  // sweep ids, oldest tick first; at most two
    app.on('sweeps', () => this.render());
    app.on('role', () => this.render());
    app.on('view', ({ view }) => { if (view === 'history') app.refreshSweeps(); });
    $('#history-bench').addEventListener('change', () => this.render());
    $('#history tbody').addEventListener('click', (e) => {
      const b = e.target.closest('button[data-start]');
      if (!b) return;
      app.command('POST', `/api/sweeps/${b.dataset.start}/start`, {}, `Sweep ${b.dataset.start} started`)
        .then(() => { app.refreshSweeps(); location.hash = `#/sweep/${b.dataset.start}`; }).catch(() => {});
    });
    $('#history tbody').addEventListener('change', (e) => {
      const c = e.target.closest('input[data-tick]');
      if (!c) return;
      const id = Number(c.dataset.tick);
      this.ticked = this.ticked.filter((x) => x !== id);
      if (c.checked) this.ticked.push(id);
      if (this.ticked.length > 2) this.ticked.shift();  // the oldest tick gives way
      this.render();
    });
    $('#history-compare').addEventListener('click', () => {
      if (this.ticked.length !== 2) return;
      const [a, b] = this.ticked.slice().sort((x, y) => x - y);
      location.hash = `#/results/${a}/vs/${b}`;
    });
  }

  render() {
    const all = this.app.sweeps || [];
    const sel = $('#history-bench');
    const names = [...new Set(all.map((s) => s.bench?.name).filter(Boolean))].sort();
    const chosen = names.includes(sel.value) ? sel.value : '';
    const opts = '<option value="">all benches</option>' + names.map((n) => `<option value="${escapeHtml(n)}">${escapeHtml(n)}</option>`).join('');
    if (sel.innerHTML !== opts) sel.innerHTML = opts;
    sel.value = chosen;
    const ids = new Set(all.map((s) => s.id));
    this.ticked = this.ticked.filter((id) => ids.has(id));
    const rows = all.filter((s) => !chosen || s.bench?.name === chosen).slice().reverse().map((s) => {
      const canStart = this.app.isOperator && !['completed', 'running', 'paused'].includes(s.state);
      const canCompare = s.points_stored > 0;
      return `<tr data-id="${s.id}" data-bench="${escapeHtml(s.bench?.name || '')}">
        <td>${canCompare ? `<input type="checkbox" data-tick="${s.id}" aria-label="compare sweep ${s.id}"${this.ticked.includes(s.id) ? ' checked' : ''}>` : ''}</td>
        <td>${s.id}</td><td>${escapeHtml(s.name)}</td><td class="bench">${escapeHtml(benchLabel(s))}</td>
        <td class="state ${escapeHtml(s.state)}">${escapeHtml(s.state)}</td>
        <td>${s.points_stored} / ${s.total_points}</td><td>${when(s.created_at)}</td><td>${when(s.finished_at)}</td>
        <td>${s.last_error ? escapeHtml(s.last_error) : ''}</td>
        <td><a href="#/sweep/${s.id}">Progress</a> · <a href="#/results/${s.id}">Results</a>
          ${canStart ? `· <button type="button" class="small" data-start="${s.id}">${s.points_stored ? 'Continue' : 'Start'}</button>` : ''}</td></tr>`;
    }).join('');
    $('#history tbody').innerHTML = rows || `<tr><td colspan="10" class="muted">${chosen ? `No sweeps of bench ${escapeHtml(chosen)}.` : 'No sweeps yet.'}</td></tr>`;
    const two = this.ticked.length === 2;
    $('#history-compare').disabled = !two;
    const bench = (id) => benchLabel(all.find((s) => s.id === id)) || 'unknown bench';
    $('#history-compare-note').textContent = two
      ? `#${this.ticked[0]} on ${bench(this.ticked[0])} against #${this.ticked[1]} on ${bench(this.ticked[1])}`
      : 'tick two runs (of any bench) to compare them';
  }
}
