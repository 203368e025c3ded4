// Client-side stand-in for GET /api/sweeps/{id}/analysis while a daemon lacks the route: the same
// JSON shape as bench::to_json(analysis) (docs/analysis.md) for the sections the dashboard draws,
// computed from the points JSON with the same rules (parabola through the smallest sample and its
// neighbours, edge minima not refined; unstable, faulted and voltage-limited points, those on a
// low-speed fallback and those the lock guard ran on the encoder left out).
const EST_ORDER = ['encoder', 'ekf-basic', 'ekf-rs', 'hfi', 'eemf-const', 'eemf-lut', 'eemf-rls'];
const cfgKey = (r) => `${r.estimator}/${r.pwm}`;
export const cfgSort = (a, b) => (EST_ORDER.indexOf(a.estimator) - EST_ORDER.indexOf(b.estimator))
  || ((a.pwm === 'capwm' ? 0 : 1) - (b.pwm === 'capwm' ? 0 : 1));

function parabola(x, y, i) {
  const [x0, x1, x2] = [x[i - 1], x[i], x[i + 1]];
  const [y0, y1, y2] = [y[i - 1], y[i], y[i + 1]];
  const den = (x0 - x1) * (x0 - x2) * (x1 - x2);
  const a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / den;
  const b = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / den;
  return { a, b, at: (xv) => { const c = y0 - a * x0 * x0 - b * x0; return a * xv * xv + b * xv + c; } };
}

function lagrange(x, y, i, xv) {
  const p = parabola(x, y, i);
  return p.at(xv);
}

function optimum(curve, key) {
  const { angles } = curve;
  const v = curve[key];
  let i = 0;
  for (let k = 1; k < v.length; k++) if (v[k] < v[i]) i = k;
  const n = angles.length;
  const pick = (k) => ({ angle_deg: angles[k], im_A: curve.im[k], pdcm_W: curve.pdcm[k], pm_W: curve.pm[k] });
  let out;
  if (n < 3 || i === 0 || i === n - 1) {
    out = { ...pick(i), refined: false, at_edge: n >= 3 };
  } else {
    const p = parabola(angles, v, i);
    let xv = p.a > 0 ? -p.b / (2 * p.a) : angles[i];
    if (!(xv >= angles[i - 1] && xv <= angles[i + 1])) xv = angles[i];
    out = { angle_deg: xv, im_A: lagrange(angles, curve.im, i, xv), pdcm_W: lagrange(angles, curve.pdcm, i, xv),
      pm_W: lagrange(angles, curve.pm, i, xv), refined: p.a > 0, at_edge: false };
  }
  out.efficiency = out.pdcm_W > 0 ? out.pm_W / out.pdcm_W : null;
  return out;
}

function histogram(values, width) {
  if (!values.length) return null;
  const lo = Math.floor(Math.min(...values) / width + 1e-9);
  const hi = Math.floor(Math.max(...values) / width + 1e-9);
  const bins = [];
  for (let k = lo; k <= hi; k++) bins.push({ from: k * width, to: (k + 1) * width, count: 0 });
  for (const v of values) bins[Math.floor(v / width + 1e-9) - lo].count++;
  const mean = values.reduce((s, v) => s + v, 0) / values.length;
  return { bin_width: width, count: values.length, min: Math.min(...values), mean, max: Math.max(...values), bins };
}

export function analyzeClient(points, reference = { estimator: 'encoder', pwm: 'capwm' }) {
  const used = [];
  const excluded = [];
  points.forEach((r, k) => {
    const reasons = [];
    if (r.unstable) reasons.push('unstable');
    if (r.fault) reasons.push('faulted');
    if (r.voltage_limited) reasons.push('voltage_limited');
    if (r.below_min_speed) reasons.push('below_min_speed');
    if (r.lock_lost) reasons.push('lock_lost');
    if (reasons.length) excluded.push({ record: k, estimator: r.estimator, pwm: r.pwm, speed_rpm: r.speed_rpm, load_Nm: r.load_Nm, angle_deg: r.angle_deg, reasons });
    else used.push(r);
  });
  // Curves
  const groups = new Map();
  for (const r of used) {
    const k = `${cfgKey(r)}|${r.speed_rpm}|${r.load_Nm}`;
    if (!groups.has(k)) groups.set(k, { estimator: r.estimator, pwm: r.pwm, speed_rpm: r.speed_rpm, load_Nm: r.load_Nm, byAngle: new Map() });
    const g = groups.get(k).byAngle;
    if (!g.has(r.angle_deg)) g.set(r.angle_deg, []);
    g.get(r.angle_deg).push(r);
  }
  const avg = (rs, f) => rs.reduce((s, r) => s + r[f], 0) / rs.length;
  const curves = [...groups.values()].map((g) => {
    const angles = [...g.byAngle.keys()].sort((a, b) => a - b);
    const c = { angles, im: angles.map((a) => avg(g.byAngle.get(a), 'im_A')), pdcm: angles.map((a) => avg(g.byAngle.get(a), 'pdcm_W')), pm: angles.map((a) => avg(g.byAngle.get(a), 'pm_W')) };
    return { estimator: g.estimator, pwm: g.pwm, speed_rpm: g.speed_rpm, load_Nm: g.load_Nm, points: angles.length, angles_deg: angles,
      mtpa: optimum(c, 'im'), me: optimum(c, 'pdcm') };
  }).sort((a, b) => cfgSort(a, b) || a.speed_rpm - b.speed_rpm || a.load_Nm - b.load_Nm);
  const configs = [];
  for (const c of curves) if (!configs.some((x) => x.estimator === c.estimator && x.pwm === c.pwm)) configs.push({ estimator: c.estimator, pwm: c.pwm });
  // Deltas
  const isRef = (c) => c.estimator === reference.estimator && c.pwm === reference.pwm;
  const refCurves = new Map(curves.filter(isRef).map((c) => [`${c.speed_rpm}|${c.load_Nm}`, c]));
  const deltas = curves.filter((c) => !isRef(c) && refCurves.has(`${c.speed_rpm}|${c.load_Nm}`)).map((c) => {
    const r = refCurves.get(`${c.speed_rpm}|${c.load_Nm}`);
    const d = (o) => ({ delta_angle_deg: c[o].angle_deg - r[o].angle_deg, delta_im_A: c[o].im_A - r[o].im_A, delta_pdcm_W: c[o].pdcm_W - r[o].pdcm_W });
    return { estimator: c.estimator, pwm: c.pwm, speed_rpm: c.speed_rpm, load_Nm: c.load_Nm, mtpa: d('mtpa'), me: d('me') };
  });
  // Histograms
  const hist = [];
  const widths = { pos_err_mean_deg: 0.5, ld_err_pct: 5, lq_err_pct: 5, rs_err_pct: 20 };
  for (const cfg of configs) {
    const rs = used.filter((r) => r.estimator === cfg.estimator && r.pwm === cfg.pwm);
    for (const [q, w] of Object.entries(widths)) {
      const h = histogram(rs.map((r) => r[q]).filter((v) => typeof v === 'number' && Number.isFinite(v)), w);
      if (h) hist.push({ ...cfg, quantity: q, unit: q.endsWith('_deg') ? 'deg' : 'pct', ...h });
    }
  }
  // Position error against load
  const pe = [];
  for (const cfg of configs) {
    const rs = used.filter((r) => r.estimator === cfg.estimator && r.pwm === cfg.pwm && typeof r.pos_err_mean_deg === 'number');
    for (const speed of [...new Set(rs.map((r) => r.speed_rpm))].sort((a, b) => a - b)) {
      const at = rs.filter((r) => r.speed_rpm === speed);
      const loads = [...new Set(at.map((r) => r.load_Nm))].sort((a, b) => a - b).map((load) => {
        const l = at.filter((r) => r.load_Nm === load);
        const m = l.map((r) => r.pos_err_mean_deg);
        return { load_Nm: load, points: l.length, min_deg: Math.min(...m), mean_deg: m.reduce((s, v) => s + v, 0) / m.length, max_deg: Math.max(...m),
          window_min_deg: Math.min(...l.map((r) => r.pos_err_min_deg ?? Infinity)), window_max_deg: Math.max(...l.map((r) => r.pos_err_max_deg ?? -Infinity)) };
      });
      pe.push({ ...cfg, speed_rpm: speed, loads });
    }
  }
  // Efficiency map at the ME angle
  const maps = configs.map((cfg) => {
    const cs = curves.filter((c) => c.estimator === cfg.estimator && c.pwm === cfg.pwm);
    const speeds = [...new Set(cs.map((c) => c.speed_rpm))].sort((a, b) => a - b);
    const loads = [...new Set(cs.map((c) => c.load_Nm))].sort((a, b) => a - b);
    const eff = speeds.map((s) => loads.map((l) => cs.find((c) => c.speed_rpm === s && c.load_Nm === l)?.me.efficiency ?? null));
    const cells = cs.map((c) => ({ speed_rpm: c.speed_rpm, load_Nm: c.load_Nm, angle_deg: c.me.angle_deg, pm_W: c.me.pm_W, pdcm_W: c.me.pdcm_W, efficiency: c.me.efficiency, refined: c.me.refined }));
    return { ...cfg, speeds_rpm: speeds, loads_Nm: loads, efficiency: eff, cells };
  });
  return {
    schema: 'synbench.analysis/1', computed_by: 'dashboard',
    options: { reference, exclude_unstable: true, exclude_faulted: true, exclude_voltage_limited: true,
      exclude_below_min_speed: true, exclude_lock_lost: true },
    points: { records: points.length, used: used.length, excluded },
    curves: { thesis_figures: '6.20', entries: curves },
    deltas: { thesis_figures: '6.21', reference, entries: deltas },
    histograms: { thesis_figures: '6.16-6.19', entries: hist },
    position_error: { thesis_figures: '6.13-6.15', entries: pe },
    efficiency_map: { thesis_figures: null, entries: maps },
  };
}

// Every configuration that appears in an analysis, in the analysis' order.
export function analysisConfigs(a) {
  const out = [];
  for (const sec of ['curves', 'efficiency_map', 'histograms']) {
    for (const e of a?.[sec]?.entries || [])
      if (!out.some((c) => c.estimator === e.estimator && c.pwm === e.pwm)) out.push({ estimator: e.estimator, pwm: e.pwm });
  }
  return out.sort(cfgSort);
}
