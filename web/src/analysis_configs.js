// The configurations (estimator x PWM) an analysis from GET /api/sweeps/{id}/analysis covers, in
// the thesis's order: the order the dashboard lists and colours them in.
const EST_ORDER = ['encoder', 'ekf-basic', 'ekf-rs', 'hfi', 'eemf-const', 'eemf-lut', 'eemf-rls'];
export const cfgSort = (a, b) => (EST_ORDER.indexOf(a.estimator) - EST_ORDER.indexOf(b.estimator))
  || ((a.pwm === 'capwm' ? 0 : 1) - (b.pwm === 'capwm' ? 0 : 1));

// Every configuration that appears in an analysis, in the analysis' order.
export function analysisConfigs(a) {
  const out = [];
  for (const sec of ['curves', 'efficiency_map', 'histograms']) {
    for (const e of a?.[sec]?.entries || [])
      if (!out.some((c) => c.estimator === e.estimator && c.pwm === e.pwm)) out.push({ estimator: e.estimator, pwm: e.pwm });
  }
  return out.sort(cfgSort);
}
