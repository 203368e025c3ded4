// While the safety supervisor's trip latches (or an alarm: a drive that did not stop), nothing
// that starts the bench is offered: Enable, a sweep's Start / continue and Create and start are
// disabled with the reason in words, and Reset trip is the emphasised action, in the Live and the
// Sweep view (issue 44, item 4). The daemon refuses them too (409 `tripped`); this says so before
// the click.
const $ = (s) => document.querySelector(s);

// Why the bench may not start now, in an operator's words; '' when it may.
export function tripReason(st) {
  const sv = st?.supervisor;
  if (sv?.alarm) return `a drive did not stop (${sv.alarm.detail}): check the bench, then Reset trip`;
  if (sv?.trip) return `the bench is tripped (${sv.trip.detail || sv.trip.fault}): clear the cause, then Reset trip`;
  return '';
}

// Every status: Enable gated, Reset trip emphasised (and shown in the Sweep view) while the trip
// latches. The Sweep view's starters take tripReason() into their own state (sweep.js).
export function renderTripControls(st, isOperator) {
  const why = tripReason(st);
  const enable = $('#btn-enable');
  if (enable) {
    if (why) {
      enable.disabled = true;
      enable.title = why;
      enable.dataset.tripDisabled = '1';
    } else if (enable.dataset.tripDisabled) {
      delete enable.dataset.tripDisabled;
      enable.title = '';
      // A sweep owning the bench (live_sweep.js) or a viewer's token may still hold it.
      enable.disabled = !!enable.dataset.sweepDisabled || !isOperator;
    }
    enable.classList.toggle('primary', !why);
  }
  for (const b of document.querySelectorAll('.reset-trip')) {
    b.classList.toggle('primary', !!why);
    if (b.dataset.onlyWhenTripped === '1') b.hidden = !why;
  }
  const note = $('#p-trip');
  if (note) { note.hidden = !why; note.textContent = why ? `Cannot start: ${why}.` : ''; }
}
