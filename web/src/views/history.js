// History view: every sweep in the daemon's store, with links to its progress and results.
import { escapeHtml } from './live.js';

const $ = (s) => document.querySelector(s);
const when = (t) => (t ? new Date(t.replace(' ', 'T')).toLocaleString() : '–');

export class HistoryView {
  constructor(app) {
    this.app = app;
    app.on('sweeps', () => this.render());
    app.on('role', () => this.render());
    app.on('view', ({ view }) => { if (view === 'history') app.refreshSweeps(); });
    $('#history tbody').addEventListener('click', (e) => {
      const b = e.target.closest('button[data-start]');
      if (!b) return;
      app.command('POST', `/api/sweeps/${b.dataset.start}/start`, {}, `Sweep ${b.dataset.start} started`)
        .then(() => { app.refreshSweeps(); location.hash = `#/sweep/${b.dataset.start}`; }).catch(() => {});
    });
  }

  render() {
    const rows = (this.app.sweeps || []).slice().reverse().map((s) => {
      const canStart = this.app.isOperator && !['completed', 'running', 'paused'].includes(s.state);
      return `<tr data-id="${s.id}">
        <td>${s.id}</td><td>${escapeHtml(s.name)}</td><td class="state ${escapeHtml(s.state)}">${escapeHtml(s.state)}</td>
        <td>${s.points_stored} / ${s.total_points}</td><td>${when(s.created_at)}</td><td>${when(s.finished_at)}</td>
        <td>${s.last_error ? escapeHtml(s.last_error) : ''}</td>
        <td><a href="#/sweep/${s.id}">Progress</a> · <a href="#/results/${s.id}">Results</a>
          ${canStart ? `· <button type="button" class="small" data-start="${s.id}">${s.points_stored ? 'Continue' : 'Start'}</button>` : ''}</td></tr>`;
    }).join('');
    $('#history tbody').innerHTML = rows || '<tr><td colspan="8" class="muted">No sweeps yet.</td></tr>';
  }
}
