// EEMF observer with constant, table or RLS parameters.
#include "emulator/firmware/estimators/eemf.hpp"

#include <cmath>

namespace synbench::emulator::firmware {

Eemf::Eemf(const EemfParams& p)
    : p_(p), fd_(p.flux_d), fq_(p.flux_q),
      tuner_(p.stiffness, p.observer_bandwidth_Hz, p.stiffness_current_filter_s, p.ts_s),
      flux_speed_([&p] {
        ActiveFluxSpeedParams f = p.flux_speed;
        f.ts_s = p.ts_s;
        return f;
      }()) {
  obs_.configure(p_.observer_bandwidth_Hz);
  eg_f_.configure(p_.emf_filter_s, p_.ts_s);
  ig_f_.configure(10 * p_.emf_filter_s, p_.ts_s);
  id_f_.configure(10 * p_.emf_filter_s, p_.ts_s);
  ed_f_.configure(p_.emf_filter_s, p_.ts_s);
  e0_f_.configure(p_.emf_filter_s, p_.ts_s);
  k_f_.configure(p_.emf_filter_s, p_.ts_s);
  scale_.configure(p_.emf_scale_filter_s, p_.ts_s);
  speed_f_.configure(p_.speed_filter_s, p_.ts_s);
  if (p_.model == EemfModel::rls) {
    rls_every_ = std::max(1, static_cast<int>(std::lround(p_.rls_sample_s / p_.ts_s)));
    rls_.emplace(p_.rls_forgetting, p_.rls_p0, rls_every_ * p_.ts_s);
    rls_warmup_intervals_ = std::lround(p_.rls_warmup_s / (rls_every_ * p_.ts_s));
  }
}

void Eemf::inductances(double ig, double id, double& ld_dyn, double& lq_static) const {
  switch (p_.model) {
    case EemfModel::constant:
      ld_dyn = p_.ld_H;
      lq_static = p_.lq_H;
      return;
    case EemfModel::lut: {
      // Deformed tables L^ = k f(i / k) (thesis 4.1, 4.2); without cross-saturation each axis
      // depends on its own current only.
      const double kd = p_.lut_ld_scale;
      ld_dyn = kd * fd_.dynamic_inductance_H(ig / kd);
      lq_static = lut_static_H(fq_, p_.lut_lq_scale, id);
      return;
    }
    case EemfModel::rls:
      ld_dyn = model_ ? model_->ld_H : p_.ld_H;
      lq_static = model_ ? model_->lq_H : p_.lq_H;
      // psi_q = L'q i_q + psi_off_q, faded out below about 0.1 A of q current, where the
      // offset over the current means nothing.
      if (model_) lq_static += model_->psi_off_d_Wb * id / (id * id + 0.01);
      return;
  }
}

Eemf::Flux Eemf::model_flux(double ig, double id) const {
  double ld_dyn = 0, lq = 0;
  switch (p_.model) {
    case EemfModel::lut:
      lq = lut_static_H(fq_, p_.lut_lq_scale, id);
      return {lut_static_H(fd_, p_.lut_ld_scale, ig) * ig, lq * id, lq};
    case EemfModel::constant:
      inductances(ig, id, ld_dyn, lq);
      return {ld_dyn * ig, lq * id, lq};
    case EemfModel::rls:
      inductances(ig, id, ld_dyn, lq);
      return {ld_dyn * ig + (model_ ? model_->psi_off_g_Wb : 0.0), lq * id, lq};
  }
  return {};
}

EmfPrediction Eemf::predict(double ig_s, double id_s, double ld_dyn, double w_rot, double did) const {
  // E = w (Psi_d(i_d) - Lq i_d) - (L'd - L'q) p i_q on the q axis: the measured e_d carries the
  // machine's L'q p i_q against the model's L'd p i_q.
  const Flux f = model_flux(ig_s, id_s);
  double lq_dyn = f.lq_static_H;
  if (p_.model == EemfModel::lut)
    lq_dyn = p_.lut_lq_scale * fq_.dynamic_inductance_H(id_s / p_.lut_lq_scale);
  else if (p_.model == EemfModel::rls && model_)
    lq_dyn = model_->lq_H;
  return {w_rot * (f.psi_g_Wb - f.lq_static_H * ig_s) - (ld_dyn - lq_dyn) * did,
          w_rot * (ld_dyn - f.lq_static_H) * id_s};
}

void Eemf::update_flux_speed(const EstimatorInput& in, double th, double ig, double id,
                             double rs) {
  const Flux f = model_flux(ig, id);
  const double c = std::cos(th), s = std::sin(th);
  flux_speed_.update(in.ualpha_V, in.ubeta_V, in.ialpha_A, in.ibeta_A, rs,
                     c * f.psi_g_Wb - s * f.psi_d_Wb, s * f.psi_g_Wb + c * f.psi_d_Wb,
                     f.lq_static_H);
}

void Eemf::update(const EstimatorInput& in) {
  const double ts = in.ts_s;
  obs_.predict(ts);  // the angle at this sample
  const double th = obs_.theta(), w = obs_.omega();
  const double c = std::cos(th), s = std::sin(th);
  const double ig = c * in.ialpha_A + s * in.ibeta_A;
  const double id = -s * in.ialpha_A + c * in.ibeta_A;
  // The last period's voltage acted about half a period ago.
  const double thu = th - 0.5 * w * ts;
  const double cu = std::cos(thu), su = std::sin(thu);
  const double ug = cu * in.ualpha_V + su * in.ubeta_V;
  const double ud = -su * in.ualpha_V + cu * in.ubeta_V;

  if (rls_) {
    // The voltage of the period that just ended belongs to this interval; the current sample
    // closes it. The mean current is taken from the samples strictly inside.
    rls_ug_sum_ += ug;
    rls_ud_sum_ += ud;
    if (++rls_count_ < rls_every_) {
      rls_ig_sum_ += ig;
      rls_id_sum_ += id;
    } else {
      const double n = rls_every_;
      const double inner = std::max(1, rls_every_ - 1);
      if (rls_have_prev_ && rls_every_ > 1) {
        rls_->update(ig - rls_ig0_, id - rls_id0_, rls_ig_sum_ / inner, rls_id_sum_ / inner,
                     rls_ug_sum_ / n, rls_ud_sum_ / n);
        ++rls_intervals_;
      }
      // Plausible estimates only, once warmed up, smoothed: the observer must not follow every
      // wobble of a 100 ms identification memory. A fresh estimator handed a running rotor (the
      // lock guard's re-arm at 700 rpm) took its first fit at once and lost the rotor in 0.1 s.
      const auto e = rls_->estimate();
      const bool plausible = e && e->rs_ohm > 0 && e->rs_ohm < 5 * p_.rs_ohm && e->ld_H > 0.01 &&
                             e->lq_H > 0.01 && e->ld_H < 2 && e->lq_H < 2;
      if (plausible && rls_intervals_ >= rls_warmup_intervals_) take_rls_fit(*e, w);
      rls_ig0_ = ig;
      rls_id0_ = id;
      rls_have_prev_ = true;
      rls_count_ = 0;
      rls_ug_sum_ = rls_ud_sum_ = rls_ig_sum_ = rls_id_sum_ = 0;
    }
    inj_g_ = p_.prbs_voltage_V * prbs_g_.advance(ts, p_.prbs_bit_s);
    inj_d_ = p_.prbs_voltage_V * prbs_d_.advance(ts, p_.prbs_bit_s);
  }

  double ld_dyn, lq;
  // Table look-ups on smoothed currents: noise must not modulate the inductances.
  inductances(ig_f_.update(ig), id_f_.update(id), ld_dyn, lq);
  const double rs = model_ ? model_->rs_ohm : p_.rs_ohm;
  double w_rot = w;
  if (p_.rotation_speed == EemfRotationSpeed::active_flux) {
    update_flux_speed(in, th, ig, id, rs);
    w_rot = flux_speed_.omega_e_rad_s();
  }
  // The current's derivative in a frame turning at the estimated ROTOR speed w_rot, not at the
  // estimated frame's own speed w + kp err: the observer's proportional path turns the frame
  // against the rotor, and with the current loops holding i_g,d in that frame the rotor sees its
  // current vector turn, a real L'd p i that the frame-relative derivative misses. Read as EEMF
  // it is an angle error of about (kp err / w) tan(th_i) L'd / (Ld - Lq): a positive feedback
  // above unity gain from about 50 deg at 500 rpm, which is why the observer lost lock at high
  // current angles in the sweeps and could not take a higher bandwidth (docs/estimators.md).
  double dig = 0.0, did = 0.0;
  if (have_prev_) {
    const double thp = th - w_rot * ts;
    const double cp = std::cos(thp), sp = std::sin(thp);
    dig = (ig - (cp * ia_prev_ + sp * ib_prev_)) / ts;
    did = (id - (-sp * ia_prev_ + cp * ib_prev_)) / ts;
  }
  ia_prev_ = in.ialpha_A;
  ib_prev_ = in.ibeta_A;
  have_prev_ = true;
  const double eg = eg_f_.update(ug - rs * ig - ld_dyn * dig + w_rot * lq * id);
  const double ed = ed_f_.update(ud - rs * id - ld_dyn * did - w_rot * lq * ig);
  double err = 0.0;
  if (p_.vector_error) {
    EmfPrediction m = predict(ig_f_.value(), id_f_.value(), ld_dyn, w_rot, did);
    m = scale_.update(ed, {e0_f_.update(m.emf_V), k_f_.update(m.slope_V_per_rad)});
    err = emf_vector_angle_error(eg, ed, m, p_.emf_floor_V);
  } else {
    err = emf_line_angle_error(eg, ed, p_.emf_floor_V);
  }
  obs_.correct(err, ts);
  speed_f_.update(obs_.speed());
  tuner_.update(obs_, ig, id);
}

void Eemf::take_rls_fit(const StatorEstimate& e, double w) {
  // From the constants the observer ran on, not a step onto the first fit.
  if (!estimate_) {
    estimate_ = StatorEstimate{p_.rs_ohm, p_.ld_H, p_.lq_H};
    model_ = RlsModel{p_.rs_ohm, p_.ld_H, p_.lq_H};
  }
  const auto toward = [this](double& x, double target, double tau_s) {
    x += p_.rls_sample_s / (tau_s + p_.rls_sample_s) * (target - x);
  };
  toward(estimate_->rs_ohm, e.rs_ohm, p_.rls_estimate_filter_s);
  toward(estimate_->ld_H, e.ld_H, p_.rls_estimate_filter_s);
  toward(estimate_->lq_H, e.lq_H, p_.rls_estimate_filter_s);
  const double tau = p_.rls_model_filter_s;
  toward(model_->rs_ohm, e.rs_ohm, tau);
  toward(model_->ld_H, e.ld_H, tau);
  toward(model_->lq_H, e.lq_H, tau);
  // The offset EMF is w J psi_off in the frame the RLS identified in, at the speed it turned at
  // (below 20 rad/s the division amplifies the fit's noise; the EEMF hands over long before).
  if (p_.rls_flux_offset && std::fabs(w) > 20.0) {
    toward(model_->psi_off_g_Wb, e.offset_d_V / w, tau);
    toward(model_->psi_off_d_Wb, -e.offset_g_V / w, tau);
  }
}

EstimatorOutput Eemf::output() const {
  EstimatorOutput o;
  o.theta_e_rad = obs_.theta();
  o.omega_e_rad_s = speed_f_.value();
  if (estimate_) {
    o.rs_ohm = estimate_->rs_ohm;
    o.ld_H = estimate_->ld_H;
    o.lq_H = estimate_->lq_H;
  }
  return o;
}

void Eemf::injection(double& ud_V, double& uq_V) const {
  ud_V = inj_g_;
  uq_V = inj_d_;
}

}  // namespace synbench::emulator::firmware
