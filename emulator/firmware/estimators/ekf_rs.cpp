#include "emulator/firmware/estimators/ekf_rs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <utility>

#include "emulator/firmware/estimators/ekf_correct.hpp"
#include "emulator/mcidc.hpp"

namespace synbench::emulator::firmware {

namespace {

bool valid_phase(int phase) { return phase >= 0 && phase < 3; }

// cos and sin of the MCIDC phase offsets, so the update needs no trigonometry beyond th_e's.
struct PhaseTrig {
  std::array<double, 3> c, s;
};
const PhaseTrig kPhaseTrig = [] {
  PhaseTrig t{};
  for (std::size_t n = 0; n < 3; ++n) {
    t.c[n] = std::cos(kPhaseOffsetRad[n]);
    t.s[n] = std::sin(kPhaseOffsetRad[n]);
  }
  return t;
}();

using Rows3 = Eigen::Matrix<double, 3, EkfRs::kN>;

// Columns where the rows of H can be non-zero.
constexpr std::array<int, 3> kRphNonzero{EkfRs::kRd, EkfRs::kRq, EkfRs::kTh};
constexpr std::array<int, 3> kIalphaNonzero{EkfRs::kId, EkfRs::kIq, EkfRs::kTh};
constexpr std::array<int, 3> kIbetaNonzero{EkfRs::kId, EkfRs::kIq, EkfRs::kTh};

// The rows of F that differ from the identity (i_d, i_q, th_e, in that order) and the predicted
// i_d, i_q, th_e, for u_dq = Park(u_alpha,beta, th_e) with cos/sin(th_e) = c, s. Back-EMF flux
// from the maps when given, else Psi = i / R'.
void process(const EkfRs::State& x, double c, double s, double ualpha, double ubeta, double ts,
             const EkfRs::FluxMaps* maps, Rows3& rows, double& id_next, double& iq_next,
             double& th_next) {
  using E = EkfRs;
  const double rd = x(E::kRd), rq = x(E::kRq), id = x(E::kId), iq = x(E::kIq);
  const double w = x(E::kW), rs = x(E::kRs);
  const double ud = c * ualpha + s * ubeta;
  const double uq = -s * ualpha + c * ubeta;
  const double inv_rd = 1.0 / rd, inv_rq = 1.0 / rq;
  // Psi_d, Psi_q and their derivatives with respect to i_d, i_q and R'd, R'q.
  double psi_d, psi_q, dpsid_did, dpsiq_diq, dpsid_drd, dpsiq_drq;
  if (maps) {
    psi_d = maps->d.psi(id);
    psi_q = maps->q.psi(iq);
    dpsid_did = maps->d.dynamic_inductance_H(id);
    dpsiq_diq = maps->q.dynamic_inductance_H(iq);
    dpsid_drd = dpsiq_drq = 0.0;
  } else {
    psi_d = id * inv_rd;
    psi_q = iq * inv_rq;
    dpsid_did = inv_rd;
    dpsiq_diq = inv_rq;
    dpsid_drd = -psi_d * inv_rd;
    dpsiq_drq = -psi_q * inv_rq;
  }
  // (The linear model keeps the thesis' w i / R' evaluation order.)
  const double dd = ud - rs * id + (maps ? w * psi_q : w * iq * inv_rq);  // R'd^-1 di_d/dt
  const double dq = uq - rs * iq - (maps ? w * psi_d : w * id * inv_rd);  // R'q^-1 di_q/dt
  const double ts_rd = ts * rd, ts_rq = ts * rq;

  id_next = id + ts_rd * dd;
  iq_next = iq + ts_rq * dq;
  th_next = x(E::kTh) + ts * w;

  rows.setZero();
  rows(0, E::kRd) = ts * dd;
  rows(0, E::kRq) = ts_rd * w * dpsiq_drq;
  rows(0, E::kId) = 1.0 - ts_rd * rs;
  rows(0, E::kIq) = ts_rd * w * dpsiq_diq;
  rows(0, E::kW) = ts_rd * psi_q;
  rows(0, E::kTh) = ts_rd * uq;
  rows(0, E::kRs) = -ts_rd * id;

  rows(1, E::kRd) = -ts_rq * w * dpsid_drd;
  rows(1, E::kRq) = ts * dq;
  rows(1, E::kId) = -ts_rq * w * dpsid_did;
  rows(1, E::kIq) = 1.0 - ts_rq * rs;
  rows(1, E::kW) = -ts_rq * psi_d;
  rows(1, E::kTh) = -ts_rq * ud;
  rows(1, E::kRs) = -ts_rq * iq;

  rows(2, E::kW) = ts;
  rows(2, E::kTh) = 1.0;
}

}  // namespace

EkfRs::EkfRs(const EkfRsParams& params) : params_(params) {
  if (params_.flux_d && params_.flux_q)
    maps_.emplace(FluxMaps{FluxAxis(*params_.flux_d), FluxAxis(*params_.flux_q)});
  const double vi = (2.0 / 3.0) * params_.sigma_i_A * params_.sigma_i_A;
  const double vrel = params_.sigma_rel_per_H * params_.sigma_rel_per_H;
  q_diag_ << vrel, vrel, vi, vi, params_.sigma_w_rad_s * params_.sigma_w_rad_s,
      params_.sigma_th_rad * params_.sigma_th_rad, params_.sigma_rs_ohm * params_.sigma_rs_ohm;
  r_rph_ = params_.sigma_rph_per_H * params_.sigma_rph_per_H;
  r_i_ = vi;
  reset();
}

EkfRs::State EkfRs::f(const State& x, double ualpha_V, double ubeta_V, double ts_s,
                      const FluxMaps* maps) {
  Rows3 rows;
  State y = x;
  process(x, std::cos(x(kTh)), std::sin(x(kTh)), ualpha_V, ubeta_V, ts_s, maps, rows, y(kId),
          y(kIq), y(kTh));
  return y;
}

EkfRs::Cov EkfRs::jacobian_f(const State& x, double ualpha_V, double ubeta_V, double ts_s,
                             const FluxMaps* maps) {
  Rows3 rows;
  double id, iq, th;
  process(x, std::cos(x(kTh)), std::sin(x(kTh)), ualpha_V, ubeta_V, ts_s, maps, rows, id, iq, th);
  Cov fm = Cov::Identity();
  fm.row(kId) = rows.row(0);
  fm.row(kIq) = rows.row(1);
  fm.row(kTh) = rows.row(2);
  return fm;
}

EkfRs::Meas2 EkfRs::h_currents(const State& x) {
  const double c = std::cos(x(kTh)), s = std::sin(x(kTh));
  return {c * x(kId) - s * x(kIq), s * x(kId) + c * x(kIq)};
}

EkfRs::Jac2 EkfRs::jacobian_h_currents(const State& x) {
  const double c = std::cos(x(kTh)), s = std::sin(x(kTh));
  const double ia = c * x(kId) - s * x(kIq), ib = s * x(kId) + c * x(kIq);
  Jac2 hm = Jac2::Zero();
  hm(0, kId) = c;
  hm(0, kIq) = -s;
  hm(0, kTh) = -ib;
  hm(1, kId) = s;
  hm(1, kIq) = c;
  hm(1, kTh) = ia;
  return hm;
}

EkfRs::Meas3 EkfRs::h(const State& x, int phase) {
  const double cp = std::cos(x(kTh) + kPhaseOffsetRad[phase]);
  const double cp2 = cp * cp;
  const Meas2 i = h_currents(x);
  return {x(kRd) * cp2 + x(kRq) * (1.0 - cp2), i(0), i(1)};
}

EkfRs::Jac3 EkfRs::jacobian_h(const State& x, int phase) {
  const double phi = x(kTh) + kPhaseOffsetRad[phase];
  const double cp = std::cos(phi), sp = std::sin(phi);
  Jac3 hm = Jac3::Zero();
  hm(0, kRd) = cp * cp;
  hm(0, kRq) = sp * sp;
  hm(0, kTh) = 2.0 * (x(kRq) - x(kRd)) * sp * cp;
  hm.bottomRows<2>() = jacobian_h_currents(x);
  return hm;
}

template <int M>
void EkfRs::correct(const Eigen::Matrix<double, M, 1>& innovation,
                    const Eigen::Matrix<double, M, kN>& hm,
                    const Eigen::Matrix<double, M, 1>& r_diag,
                    const std::array<std::array<int, 3>, M>& nonzero) {
  // Each row of H has three non-zeros: P H^T from three columns of P per row.
  Eigen::Matrix<double, kN, M> pht;
  for (int r = 0; r < M; ++r) {
    const auto& nz = nonzero[static_cast<std::size_t>(r)];
    pht.col(r) = p_.col(nz[0]) * hm(r, nz[0]) + p_.col(nz[1]) * hm(r, nz[1]) +
                 p_.col(nz[2]) * hm(r, nz[2]);
  }
  Eigen::Matrix<double, M, M> sm = hm * pht;
  sm.diagonal() += r_diag;
  ekf_correct(x_, p_, pht, sm, innovation);
}

void EkfRs::update(const EstimatorInput& in) {
  const double ts = in.ts_s > 0 ? in.ts_s : params_.ts_s;

  // Predict. F differs from I only in rows i_d, i_q, th_e, so F P F^T needs 2 dense rows and
  // 2 dense columns of products plus the th_e row and column, not two full 7x7 products.
  {
    const double c = std::cos(x_(kTh)), s = std::sin(x_(kTh));
    Rows3 rows;
    double id, iq, th;
    process(x_, c, s, in.ualpha_V, in.ubeta_V, ts, flux_maps(), rows, id, iq, th);
    const bool rs_free = std::abs(x_(kW)) >= params_.rs_speed_threshold_rad_s;
    x_(kId) = id;
    x_(kIq) = iq;
    x_(kTh) = th;

    // Row th_e of F is e_th + Ts e_w; rows i_d, i_q are dense.
    const Eigen::Matrix<double, 2, kN> fp = rows.topRows<2>() * p_;  // rows i_d, i_q of F P
    p_.row(kTh) += ts * p_.row(kW);
    p_.row(kId) = fp.row(0);
    p_.row(kIq) = fp.row(1);
    const Eigen::Matrix<double, kN, 2> fpf = p_ * rows.topRows<2>().transpose();  // of F P F^T
    p_.col(kTh) += ts * p_.col(kW);
    p_.col(kId) = fpf.col(0);
    p_.col(kIq) = fpf.col(1);
    State q = q_diag_;
    if (!rs_free) q(kRs) = 0.0;
    p_.diagonal() += q;
  }

  // Correct. Innovations and Jacobian rows at the predicted state.
  const double c = std::cos(x_(kTh)), s = std::sin(x_(kTh));
  const double id = x_(kId), iq = x_(kIq);
  const double ia = c * id - s * iq, ib = s * id + c * iq;
  if (in.mcidc_phase && valid_phase(*in.mcidc_phase)) {
    const auto n = static_cast<std::size_t>(*in.mcidc_phase);
    const double cp = c * kPhaseTrig.c[n] - s * kPhaseTrig.s[n];  // cos(th_e + th_phN)
    const double sp = s * kPhaseTrig.c[n] + c * kPhaseTrig.s[n];  // sin(th_e + th_phN)
    const double cp2 = cp * cp, sp2 = sp * sp;
    Jac3 hm = Jac3::Zero();
    hm(0, kRd) = cp2;
    hm(0, kRq) = sp2;
    hm(0, kTh) = 2.0 * (x_(kRq) - x_(kRd)) * sp * cp;
    hm(1, kId) = c;
    hm(1, kIq) = -s;
    hm(1, kTh) = -ib;
    hm(2, kId) = s;
    hm(2, kIq) = c;
    hm(2, kTh) = ia;
    const Meas3 innovation{in.mcidc_reluctance_per_H - (x_(kRd) * cp2 + x_(kRq) * sp2),
                           in.ialpha_A - ia, in.ibeta_A - ib};
    correct<3>(innovation, hm, Meas3{r_rph_, r_i_, r_i_},
               {kRphNonzero, kIalphaNonzero, kIbetaNonzero});
  } else {
    Jac2 hm = Jac2::Zero();
    hm(0, kId) = c;
    hm(0, kIq) = -s;
    hm(0, kTh) = -ib;
    hm(1, kId) = s;
    hm(1, kIq) = c;
    hm(1, kTh) = ia;
    correct<2>(Meas2{in.ialpha_A - ia, in.ibeta_A - ib}, hm, Meas2{r_i_, r_i_},
               {kIalphaNonzero, kIbetaNonzero});
  }

  x_(kRs) = std::max(x_(kRs), params_.min_rs_ohm);
  // (R'd, R'q, i_d, i_q, th) -> (R'q, R'd, i_q, -i_d, th + pi/2): same f and h for the linear
  // model. With flux maps the axes are no longer interchangeable in f, and the map is a
  // re-labelling onto the convention the maps assume (it happens during the first
  // milliseconds from the symmetric x0, before the currents carry information).
  if (floor_and_order_reluctances(params_.min_reluctance_per_H, params_.enforce_ld_above_lq)) {
    const double id_old = x_(kId);
    x_(kId) = x_(kIq);
    x_(kIq) = -id_old;
    // P <- J P J^T with J the signed permutation above.
    p_.row(kId).swap(p_.row(kIq));
    p_.col(kId).swap(p_.col(kIq));
    p_.row(kIq) *= -1.0;
    p_.col(kIq) *= -1.0;
  }
  x_(kTh) = wrap_pi(x_(kTh));
}

EstimatorOutput EkfRs::output() const {
  EstimatorOutput out = core_output();
  out.rs_ohm = x_(kRs);
  return out;
}

}  // namespace synbench::emulator::firmware
