// One PWM period of the whole bench: sense, run both drives' firmware, integrate the plant.
#include "emulator/twin.hpp"

#include <algorithm>
#include <cmath>

namespace synbench::emulator {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Disabled inverter: the freewheeling diodes drive the currents to zero within a millisecond;
// modelled as a resistive clamp that stays explicit-stable at the 100 us step.
constexpr double kGatesOffOhm = 500.0;
// Below this speed the braking torque fades so that it never drives the shaft backwards.
constexpr double kBrakeFadeRadS = 0.5;

double brake_direction(double wm) { return std::clamp(wm / kBrakeFadeRadS, -1.0, 1.0); }

}  // namespace

struct Twin::Rates {
  PlantState dx;
  double pac_W = 0, pcu_W = 0, pfe_W = 0, pmech_W = 0, pm_W = 0;
  double idcm_A = 0, idcg_A = 0;
  SynrmFlows flows;
  double ud = 0, uq = 0, load_torque_Nm = 0;
};

Twin::Twin(const TwinConfig& config)
    : cfg_(config),
      ts_(config.step_s()),
      synrm_(config.plant_synrm()),
      inverter_(config.inverter),
      bus_(config.dc_bus),
      vfc_(config.vfc),
      mcidc_(config.mcidc, config.step_s()),
      thermal_(config.thermal),
      synrm_fw_(config),
      load_fw_(config),
      noise_(static_cast<std::uint64_t>(config.sim.seed_int)),
      counts_per_rev_(std::ldexp(1.0, config.encoder.resolution_bits)),
      encoder_offset_rad_(config.plant.encoder_offset_deg * kPi / 180.0 / config.synrm.pole_pairs),
      total_inertia_kgm2_(config.plant_synrm().inertia_kgm2 + config.load.inertia_kgm2),
      load_kt_(1.5 * config.load.pole_pairs * config.load.psi_pm_Wb) {
  x_.udc_V = bus_.voltage_V();
}

Twin::Rates Twin::evaluate(const PlantState& x, double ua, double ub, bool gates, double rs,
                           double load_iref, double p_inv_m, double p_inv_g) const {
  const double th = synrm_.pole_pairs() * x.angle_rad;
  return evaluate_at(x, std::cos(th), std::sin(th),
                     synrm_.flows(x.psi_d_Wb, x.psi_q_Wb, 0.0, 0.0, synrm_.pole_pairs() * x.speed_rad_s, rs), ua, ub,
                     gates, rs, load_iref, p_inv_m, p_inv_g);
}

Twin::Rates Twin::evaluate_at(const PlantState& x, double c, double s, SynrmFlows flows, double ua, double ub,
                              bool gates, double rs, double load_iref, double p_inv_m, double p_inv_g) const {
  Rates r;
  double ud = c * ua + s * ub, uq = -s * ua + c * ub;
  r.flows = flows;
  if (!gates) {
    ud = -kGatesOffOhm * r.flows.id;
    uq = -kGatesOffOhm * r.flows.iq;
  }
  r.flows.dpsi_d += ud;
  r.flows.dpsi_q += uq;
  r.ud = ud;
  r.uq = uq;

  const double wm = x.speed_rad_s;
  const double tl = load_kt_ * x.load_iq_A * brake_direction(wm);
  r.load_torque_Nm = tl;
  const double b1g = cfg_.load.b1_Nms_per_rad;
  r.dx.psi_d_Wb = r.flows.dpsi_d;
  r.dx.psi_q_Wb = r.flows.dpsi_q;
  r.dx.speed_rad_s = (r.flows.torque_Nm - tl - synrm_.friction_torque_Nm(wm) - b1g * wm) /
                     total_inertia_kgm2_;
  r.dx.angle_rad = wm;
  r.dx.load_iq_A = (load_iref - x.load_iq_A) * 2.0 * kPi * cfg_.load.current_bandwidth_Hz;

  r.pac_W = 1.5 * (ud * r.flows.id + uq * r.flows.iq);
  r.pcu_W = 1.5 * rs * (r.flows.id * r.flows.id + r.flows.iq * r.flows.iq);
  r.pfe_W = r.flows.pfe_W;
  r.pmech_W = synrm_.friction_loss_W(wm);
  r.pm_W = tl * wm + b1g * wm * wm;
  const double p_cu_g = 1.5 * cfg_.load.rs_ohm * x.load_iq_A * x.load_iq_A;
  r.idcm_A = (r.pac_W + p_inv_m) / x.udc_V;
  r.idcg_A = (tl * wm - p_cu_g - p_inv_g) / x.udc_V;
  r.dx.udc_V = bus_.derivative(x.udc_V, r.idcm_A - r.idcg_A, faults_.source_offset_V);
  return r;
}

double Twin::load_inverter_loss_W(const PlantState& x) const {
  // Load PMSM in motor convention: i_q opposes rotation; steady-state terminal voltage.
  const auto& l = cfg_.load;
  const double iq = -x.load_iq_A * brake_direction(x.speed_rad_s);
  if (iq == 0.0) return 0.0;
  const double we = l.pole_pairs * x.speed_rad_s;
  const double ud = -we * l.ls_H * iq, uq = l.rs_ohm * iq + we * l.psi_pm_Wb;
  const double th = l.pole_pairs * x.angle_rad;
  const double c = std::cos(th), s = std::sin(th);
  const Phases i = to_phases(-s * iq, c * iq);
  const Phases d = InverterModel::duties(c * ud - s * uq, s * ud + c * uq, x.udc_V);
  return inverter_.loss_W(i, d, x.udc_V, drivers::Pwm::capwm);
}

void Twin::step() {
  if (window_pending_ > 0) {
    window_left_ = window_pending_;
    window_pending_ = 0;
    synrm_fw_.begin_window(window_left_);
    load_fw_.begin_window(window_left_);
    // The meter times its gate from the gate edge (its own time base): whole periods, exactly,
    // wherever on the twin's clock the window starts.
    vfc_.open_gate(0.0);
    window_steps_ = window_left_;
    const std::int64_t b = cfg_.firmware.window_batches;
    batch_steps_ = window_steps_ >= b && window_steps_ % b == 0 ? window_steps_ / b : 0;
    t_pin_ = t_pcu_ = t_pfe_ = t_pmech_ = t_pinv_ = t_pm_ = t_temp_ = 0;
  }

  const double rs = synrm_.rs_ohm(thermal_.temp_C());
  const bool gates = applied_.gates_on;
  const double udc = x_.udc_V;

  // Actual phase currents at the start of the period: sensors, dead time and inverter loss.
  const double th = synrm_.pole_pairs() * x_.angle_rad;
  const double c = std::cos(th), s = std::sin(th);
  const SynrmFlows cur = synrm_.flows(x_.psi_d_Wb, x_.psi_q_Wb, 0, 0,
                                      synrm_.pole_pairs() * x_.speed_rad_s, rs);
  const Phases i_ph = to_phases(c * cur.id - s * cur.iq, s * cur.id + c * cur.iq);

  double ua = applied_.ualpha_V, ub = applied_.ubeta_V;
  double p_inv_m = 0;
  if (gates) {
    Phases err;
    for (int n = 0; n < 3; ++n) err[n] = inverter_.dead_time_error_V(i_ph[n], udc);
    double ea, eb;
    to_alpha_beta(err, ea, eb);
    ua += ea;
    ub += eb;
    p_inv_m = inverter_.loss_W(i_ph, applied_.duty, udc, applied_.pwm);
  }
  const double p_inv_g = load_inverter_loss_W(x_);

  if (synrm_fw_.needs_mcidc() && gates) {
    mcidc_sample_ = mcidc_.measure(steps_, applied_.pwm, applied_.duty, th,
                                   synrm_.d_axis().dynamic_inductance_H(cur.id0),
                                   synrm_.q_axis().dynamic_inductance_H(cur.iq0), noise_,
                                   applied_.mcidc_window_shift);
  } else {
    mcidc_sample_.reset();
  }

  // Both drives sample and compute the command for the next period (one period of delay).
  const double sigma = cfg_.firmware.current_noise_sigma_A;
  firmware::DriveSample sample;
  sample.ia_A = i_ph[0] + sigma * noise_.gauss() + faults_.phase_a_sensor_offset_A;
  sample.ib_A = i_ph[1] + sigma * noise_.gauss();
  sample.encoder_count = static_cast<std::int64_t>(std::floor((x_.angle_rad + encoder_offset_rad_) / (2.0 * kPi) * counts_per_rev_));
  sample.udc_V = udc;
  sample.temp_C = thermal_.temp_C();
  sample.mcidc = mcidc_sample_;
  const firmware::DriveOutput next = synrm_fw_.control(sample);
  const double load_iref = load_fw_.control(x_.load_iq_A + sigma * noise_.gauss());

  // Heun: slope at the start, Euler predictor, slope at the end, average.
  const Rates k1 = evaluate_at(x_, c, s, cur, ua, ub, gates, rs, load_iref_A_, p_inv_m, p_inv_g);
  PlantState xp = x_;
  xp.psi_d_Wb += ts_ * k1.dx.psi_d_Wb;
  xp.psi_q_Wb += ts_ * k1.dx.psi_q_Wb;
  xp.speed_rad_s += ts_ * k1.dx.speed_rad_s;
  xp.angle_rad += ts_ * k1.dx.angle_rad;
  xp.udc_V += ts_ * k1.dx.udc_V;
  xp.load_iq_A += ts_ * k1.dx.load_iq_A;
  const Rates k2 = evaluate(xp, ua, ub, gates, rs, load_iref_A_, p_inv_m, p_inv_g);
  const double h = 0.5 * ts_;
  x_.psi_d_Wb += h * (k1.dx.psi_d_Wb + k2.dx.psi_d_Wb);
  x_.psi_q_Wb += h * (k1.dx.psi_q_Wb + k2.dx.psi_q_Wb);
  x_.speed_rad_s += h * (k1.dx.speed_rad_s + k2.dx.speed_rad_s);
  x_.angle_rad += h * (k1.dx.angle_rad + k2.dx.angle_rad);
  x_.udc_V += h * (k1.dx.udc_V + k2.dx.udc_V);
  x_.load_iq_A += h * (k1.dx.load_iq_A + k2.dx.load_iq_A);
  bus_.set_voltage(x_.udc_V);

  const double pcu = 0.5 * (k1.pcu_W + k2.pcu_W), pfe = 0.5 * (k1.pfe_W + k2.pfe_W);
  thermal_.step(pcu + pfe, ts_);
  vfc_.integrate(0.5 * (k1.idcm_A + k2.idcm_A), 0.5 * (k1.idcg_A + k2.idcg_A), ts_);

  applied_ = next;
  load_iref_A_ = load_iref;
  ++steps_;

  if (window_left_ > 0) {
    // The meter latches its counters at each sub-gate boundary (the drives' batch boundaries).
    const std::int64_t done = window_steps_ - window_left_ + 1;
    if (batch_steps_ > 0 && done % batch_steps_ == 0 && done < window_steps_) vfc_.end_batch();
    t_pin_ += 0.5 * (k1.pac_W + k2.pac_W);
    t_pcu_ += pcu;
    t_pfe_ += pfe;
    t_pmech_ += 0.5 * (k1.pmech_W + k2.pmech_W);
    t_pinv_ += p_inv_m;
    t_pm_ += 0.5 * (k1.pm_W + k2.pm_W);
    t_temp_ += thermal_.temp_C();
    if (--window_left_ == 0) {
      vfc_.close_gate(static_cast<double>(window_steps_) * ts_);
      const double n = std::round(vfc_.reading().gate_s / ts_);
      truth_ = drivers::TruthWindow{t_pin_ / n,   t_pcu_ / n, t_pfe_ / n, t_pmech_ / n,
                                    t_pinv_ / n,  t_pm_ / n,  t_temp_ / n};
    }
  }
}

void Twin::open_window(double window_s) {
  window_pending_ = std::max<std::int64_t>(1, std::llround(window_s / ts_));
  // Whole batches: the drives, the meter's gate and the truth all last the rounded length.
  const std::int64_t b = cfg_.firmware.window_batches;
  if (window_pending_ >= b) window_pending_ = std::llround(static_cast<double>(window_pending_) / static_cast<double>(b)) * b;
  truth_.reset();
}

PlantSnapshot Twin::snapshot() const {
  const double rs = synrm_.rs_ohm(thermal_.temp_C());
  const Rates r = evaluate(x_, applied_.ualpha_V, applied_.ubeta_V, applied_.gates_on, rs,
                           load_iref_A_, 0, 0);
  PlantSnapshot p;
  p.id_A = r.flows.id;
  p.iq_A = r.flows.iq;
  p.id0_A = r.flows.id0;
  p.iq0_A = r.flows.iq0;
  p.torque_Nm = r.flows.torque_Nm;
  p.load_torque_Nm = r.load_torque_Nm;
  p.speed_rpm = x_.speed_rad_s * 60.0 / (2.0 * kPi);
  p.udc_V = x_.udc_V;
  p.temp_C = thermal_.temp_C();
  p.ud_V = r.ud;
  p.uq_V = r.uq;
  p.brake_on = bus_.brake_on();
  return p;
}

}  // namespace synbench::emulator
