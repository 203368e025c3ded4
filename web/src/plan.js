// Sweep plans on the client: expansion of a canonical plan into its points (grid mode; the same
// order and indices as bench::expand, docs/sweep-plan.md), and the bench-time estimate used when
// the daemon has no POST /api/sweeps/estimate; the curves of a plan, its description in words and
// its setpoints against the bench's limits.
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

// The (speed, load, configuration) curves of a plan in sweep order, numbered as bench::plan_groups
// numbers them (an adaptive point's index is group * max_evaluations + evaluation).
export function expandGroups(plan) {
  if (!plan) return [];
  const d = plan.dimensions || {};
  const one = { ...plan, mode: 'grid', dimensions: { ...d, angle_deg: [0] } };
  return expandPlan(one).map(({ index, angle_deg, ...g }) => ({ group: index, ...g }));
}

const PWM_LABEL = { capwm: 'CAPWM', aspwm: 'ASPWM' };
const span = (list, unit) => {
  const lo = Math.min(...list), hi = Math.max(...list);
  return lo === hi ? `${lo} ${unit}` : `${lo}..${hi} ${unit}`;
};

// What a plan measures, in words, from the plan itself (a preset's description must say what it
// loads): "5 speeds 100..900 rpm x 7 loads 0.5..3.5 N m x 19 angles 40..76 deg x 8 configurations
// (encoder/CAPWM, ...): 4522 points".
export function describePlan(plan) {
  if (!plan) return '';
  const d = plan.dimensions || {};
  const parts = [];
  if (d.operating_points?.length) {
    const ops = d.operating_points;
    parts.push(`${ops.length} operating point${ops.length === 1 ? '' : 's'} (${span(ops.map((p) => p.speed_rpm), 'rpm')}, ${span(ops.map((p) => p.load_Nm), 'N m')})`);
  } else {
    const s = values(d.speed_rpm), l = values(d.load_Nm);
    parts.push(`${s.length} speed${s.length === 1 ? '' : 's'} ${span(s, 'rpm')}`, `${l.length} load${l.length === 1 ? '' : 's'} ${span(l, 'N m')}`);
  }
  const adaptive = plan.mode === 'adaptive';
  if (adaptive) parts.push(`adaptive angle search in ${(plan.adaptive?.bracket_deg || [40, 76]).join('..')} deg`);
  else { const a = values(d.angle_deg); parts.push(`${a.length} angle${a.length === 1 ? '' : 's'} ${span(a, 'deg')}`); }
  const configs = d.configurations?.length ? d.configurations : [{ estimator: 'encoder', pwm: 'capwm' }];
  parts.push(`${configs.length} configuration${configs.length === 1 ? '' : 's'} (${configs.map((c) => `${c.estimator}/${PWM_LABEL[c.pwm] || c.pwm}`).join(', ')})`);
  const points = adaptive ? expandGroups(plan).length * (plan.adaptive?.max_evaluations ?? 7) : expandPlan(plan).length;
  return `${parts.join(' x ')}: ${adaptive ? 'at most ' : ''}${points} points`;
}

// The plan's setpoints against the bench's limits (GET /api/bench/config): [{pointer, message}],
// at the pointers the daemon uses (bench/sweep_plan_bench_limits.hpp). Empty without limits.
export function benchLimitErrors(plan, config) {
  const out = [];
  const maxS = config?.speed_rpm?.max, maxL = config?.load_Nm?.max;
  const d = plan?.dimensions || {};
  const over = (pointer, v, max, unit, what) => {
    if (max != null && Number.isFinite(v) && v > max) out.push({ pointer, message: `${v} ${unit} exceeds the bench's ${what} (${max} ${unit})` });
  };
  if (d.operating_points) {
    d.operating_points.forEach((p, i) => {
      over(`/dimensions/operating_points/${i}/speed_rpm`, p.speed_rpm, maxS, 'rpm', 'max_speed_rpm');
      over(`/dimensions/operating_points/${i}/load_Nm`, p.load_Nm, maxL, 'N m', 'max_load_Nm');
    });
  } else {
    const s = values(d.speed_rpm), l = values(d.load_Nm);
    if (s.length) over('/dimensions/speed_rpm', Math.max(...s), maxS, 'rpm', 'max_speed_rpm');
    if (l.length) over('/dimensions/load_Nm', Math.max(...l), maxL, 'N m', 'max_load_Nm');
  }
  return out;
}
