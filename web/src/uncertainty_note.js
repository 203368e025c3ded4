// The Results view's line on a sweep's uncertainty (issue 26, docs/uncertainty.md): how many points
// carry a standard uncertainty, and how many of the ME - MTPA differences and of the deltas against
// the reference are significant at 95 % (of those whose significance is known); or, for a sweep
// whose points carry none (measured before the record had u, or on devices without batches),
// "no uncertainty stored": then no chart draws bars and nothing is called significant.
import { known, NO_U_NOTE } from './errorbars.js';

// "k of n": how many of the values whose significance is known (true or false) are true.
export function significantCount(values) {
  const k = values.filter((v) => v === true || v === false);
  return { significant: k.filter((v) => v).length, known: k.length };
}

export function uncertaintyNote(points, analysis) {
  const withU = (points || []).filter((p) => known(p.pdcm_u_W)).length;
  if (!withU) return `${NO_U_NOTE[0].toUpperCase()}${NO_U_NOTE.slice(1)} for this sweep: its points carry no u (measured before the record had one, or without batches), so no error bars and no significance.`;
  const curves = analysis?.curves?.entries || [];
  const deltas = analysis?.deltas?.entries || [];
  const parts = [];
  const say = (what, { significant, known: n }) => n && parts.push(`${what} significant in ${significant} of ${n}`);
  say('ME − MTPA angle', significantCount(curves.map((c) => c.me_minus_mtpa_significant)));
  say('ΔI_m (MTPA)', significantCount(deltas.map((d) => d.mtpa?.delta_im_significant)));
  say('ΔP_dcM (ME)', significantCount(deltas.map((d) => d.me?.delta_pdcm_significant)));
  return `Uncertainty (GUM, docs/uncertainty.md): ${withU} of ${points.length} points carry u; bars show ±2u (95 %), tooltips value ± u (k=1)`
    + `${parts.length ? `; ${parts.join('; ')} (at 95 %)` : ''}.`;
}

// The sweep's "measure until sure" outcome (analysis.sweep_outcome, docs/sweep-plan.md): how many
// points the adaptive searches used against the 2-deg grid's, how many curves met the angle u
// target, and how many points stayed above the precision target; '' when the plan had neither.
export function outcomeNote(outcome) {
  const parts = [];
  const a = outcome?.adaptive;
  if (a) {
    parts.push(`adaptive search: ${a.points_used} points used against ${a.grid_points} on the ${a.grid_step_deg}° grid`);
    if (a.angle_u_target_deg != null) {
      parts.push(`angle u target ${a.angle_u_target_deg}° met on ${a.curves_target_met} of ${(a.curves || []).length} curves`);
    }
  }
  const p = outcome?.precision;
  if (p) parts.push(`P_dcM u target ${p.pdcm_u_repeat_target_W} W: ${p.points_missed} of ${p.points} points above it`);
  return parts.length ? `Measure until sure: ${parts.join('; ')}.` : '';
}
