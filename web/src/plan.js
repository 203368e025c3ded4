// Sweep plans on the client: expansion of a canonical plan into its points (grid mode; the same
// order and indices as bench::expand, docs/sweep-plan.md), and the bench-time estimate used when
// the daemon has no POST /api/sweeps/estimate.
export const ESTIMATORS = ['encoder', 'ekf-basic', 'ekf-rs', 'hfi', 'eemf-const', 'eemf-lut', 'eemf-rls'];

export function values(dim) {
  if (dim == null) return [];
  if (Array.isArray(dim)) return dim;
  const { from, to, step } = dim;
  const out = [];
  if (!(step > 0)) return out;
  for (let i = 0; i <= 10000; i++) {
    const v = Math.round((from + i * step) * 1e9) / 1e9;
    if (v > to + 1e-9) break;
    out.push(v);
  }
  return out;
}

// Grid-mode points in sweep order: [{index, speed_rpm, load_Nm, angle_deg, estimator, pwm}], or
// null in adaptive mode (angles are not known in advance).
export function expandPlan(plan) {
  if (!plan || plan.mode === 'adaptive') return null;
  const d = plan.dimensions || {};
  const order = (plan.order || 'speed-load-config-angle').split('-');
  const configs = d.configurations?.length ? d.configurations : [{ estimator: 'encoder', pwm: 'capwm' }];
  const angles = values(d.angle_deg);
  let loops = order;
  let pairs = null;
  if (d.operating_points) {
    pairs = d.operating_points;
    const first = order.indexOf('speed') < order.indexOf('load') ? 'speed' : 'load';
    loops = order.filter((x) => x === first || (x !== 'speed' && x !== 'load')).map((x) => (x === first ? 'pair' : x));
  }
  const dims = {
    speed: values(d.speed_rpm).map((v) => ({ speed_rpm: v })),
    load: values(d.load_Nm).map((v) => ({ load_Nm: v })),
    pair: (pairs || []).map((p) => ({ speed_rpm: p.speed_rpm, load_Nm: p.load_Nm })),
    config: configs.map((c) => ({ estimator: c.estimator, pwm: c.pwm, _min: c.min_speed_rpm ?? 0, _max: c.max_speed_rpm ?? Infinity })),
    angle: angles.map((v) => ({ angle_deg: v })),
  };
  const out = [];
  const rec = (k, acc) => {
    if (k === loops.length) {
      if (acc.speed_rpm < acc._min || acc.speed_rpm > acc._max) return;
      const { _min, _max, ...p } = acc;
      out.push({ index: out.length, ...p });
      return;
    }
    for (const v of dims[loops[k]]) rec(k + 1, { ...acc, ...v });
  };
  rec(0, {});
  return out;
}

export function fmtDuration(s) {
  if (s == null || !Number.isFinite(s)) return '–';
  s = Math.round(s);
  if (s < 90) return `${s} s`;
  if (s < 3600) return `${Math.floor(s / 60)} min ${String(s % 60).padStart(2, '0')} s`;
  return `${Math.floor(s / 3600)} h ${String(Math.floor((s % 3600) / 60)).padStart(2, '0')} min`;
}
