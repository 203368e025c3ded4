// HFI: carrier, band-pass, heterodyne demodulation, PLL.
#include "emulator/firmware/estimators/hfi.hpp"

#include <cmath>

namespace synbench::emulator::firmware {
namespace {
constexpr double kPi = 3.14159265358979323846;
}

Hfi::Hfi(const HfiParams& p)
    : p_(p), align_steps_(std::lround(p.align_s / p.ts_s)),
      tuner_(p.stiffness, p.pll_bandwidth_Hz, p.stiffness_current_filter_s, p.ts_s) {
  w_hf_ = 2.0 * kPi * p_.frequency_Hz;
  // A command computed now acts over the period after next: its centre is 1.5 periods later.
  delay_rad_ = 1.5 * w_hf_ * p_.ts_s;
  // Demodulated q-axis response per radian of error (small angles): (U/w)(1/Lq - 1/Ld).
  gain_A_per_rad_ = p_.voltage_V / w_hf_ * (1.0 / p_.lq_hf_H - 1.0 / p_.ld_hf_H);
  bp_d_.configure(p_.frequency_Hz, p_.bandpass_bandwidth_Hz, 1.0 / p_.ts_s);
  bp_q_.configure(p_.frequency_Hz, p_.bandpass_bandwidth_Hz, 1.0 / p_.ts_s);
  demod_.configure(p_.demod_lowpass_s, p_.ts_s);
  pll_.configure(p_.pll_bandwidth_Hz);
}

void Hfi::update(const EstimatorInput& in) {
  pll_.predict(in.ts_s);  // the angle at this sample
  const double th = pll_.theta();
  const double c = std::cos(th), s = std::sin(th);
  const double id = c * in.ialpha_A + s * in.ibeta_A;
  const double iq = -s * in.ialpha_A + c * in.ibeta_A;
  const double hf_d = bp_d_.update(id);
  const double hf_q = bp_q_.update(iq);
  // The PLL must outrun the shaft's angle-error growth at this operating point.
  tuner_.update(pll_, id - hf_d, iq - hf_q);
  // The current integrates the cosine carrier: its response is a sine, delayed with the command.
  const double ref = std::sin(w_hf_ * static_cast<double>(step_) * p_.ts_s - delay_rad_);
  const double eps = demod_.update(2.0 * hf_q * ref);
  // eps = -(U/2w)(1/Lq - 1/Ld) sin(2 th_err): negative when the estimate lags.
  pll_.correct(-eps / gain_A_per_rad_, in.ts_s);
  ++step_;
}

EstimatorOutput Hfi::output() const {
  EstimatorOutput o;
  o.theta_e_rad = pll_.theta();
  o.omega_e_rad_s = pll_.omega();  // the noisy carrier: the smoother integral part
  return o;
}

void Hfi::injection(double& ud_V, double& uq_V) const {
  // step_ already counts this period's update: the carrier sample of this period.
  ud_V = p_.voltage_V * std::cos(w_hf_ * static_cast<double>(step_ - 1) * p_.ts_s);
  uq_V = 0.0;
}

void Hfi::fundamental(double& id_A, double& iq_A) const {
  id_A -= bp_d_.value();
  iq_A -= bp_q_.value();
}

}  // namespace synbench::emulator::firmware
