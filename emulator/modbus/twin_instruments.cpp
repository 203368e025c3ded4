// Totalizers and power meter of the twin's VFC channels.
#include "emulator/modbus/twin_instruments.hpp"

#include <cmath>

#include "drivers/profile_devices/totalizer_window.hpp"

namespace synbench::emulator {

TwinInstruments::TwinInstruments(const Twin& twin, const std::vector<drivers::DeviceProfile>& profiles)
    : f0_Hz_(twin.config().vfc.f0_Hz), kf_Hz_per_A_(twin.config().vfc.kf_Hz_per_A) {
  for (const drivers::DeviceProfile& p : profiles)
    if (p.kind == drivers::DeviceKind::vfc_meter && p.meter == drivers::MeterKind::totalizer)
      time_base_Hz_ = p.time_base_Hz;
  t0_s_ = t_last_s_ = twin.time_s();
}

void TwinInstruments::update(const Twin& twin) {
  const double now = twin.time_s();
  udc_sum_Vs_ += twin.state().udc_V * (now - t_last_s_);
  t_last_s_ = now;
  const double dt = now - t0_s_;
  if (dt < kPowerInterval_s - 1e-9) return;
  // Currents from the pulses over the interval with the nominal calibration, as the gate does.
  const double m = twin.vfc().pulses_m(), g = twin.vfc().pulses_g();
  const double udc = udc_sum_Vs_ / dt;
  pdcm_W_ = udc * ((m - m0_) / dt - f0_Hz_) / kf_Hz_per_A_;
  pdcg_W_ = udc * ((g - g0_) / dt - f0_Hz_) / kf_Hz_per_A_;
  t0_s_ = now;
  m0_ = m;
  g0_ = g;
  udc_sum_Vs_ = 0;
}

std::optional<double> TwinInstruments::value(const Twin& twin, const drivers::ProfileSignal& s) const {
  const auto counter = [&](double count, std::uint64_t start) {
    const std::uint64_t range = drivers::counter_range(s);
    return static_cast<double>((static_cast<std::uint64_t>(count) + start) % range);
  };
  if (s.name == "total_m") return counter(twin.vfc().pulses_m(), start_[0]);
  if (s.name == "total_g") return counter(twin.vfc().pulses_g(), start_[1]);
  if (s.name == "time_base_ticks") return counter(std::floor(twin.time_s() * time_base_Hz_ + 1e-6), start_[2]);
  if (s.name == "pdcm_W") return pdcm_W_;
  if (s.name == "pdcg_W") return pdcg_W_;
  return std::nullopt;
}

}  // namespace synbench::emulator
