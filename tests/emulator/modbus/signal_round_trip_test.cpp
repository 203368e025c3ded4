// Round trips of the device structs through the register map: the twin serves a struct of
// chosen values (distinct and non-zero, so two swapped signals fail), the RegisterServer
// encodes it as its profile says, the profile devices read it over the in-process register
// bus, and the struct they decode equals the twin's in every signal of its table. And a
// profile naming a signal the twin has no value for is refused when the twin is built.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/device_signals.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "emulator/modbus/twin_register_bus.hpp"
#include "emulator/modbus/twin_service.hpp"
#include "tests/drivers/default_profiles.hpp"

namespace synbench::emulator {
namespace {

using drivers::DeviceKind;
using drivers::DriveState;
using drivers::Fault;

using testing::default_profiles;

// What a register can carry back of `v`: half a step of an integer register, a float's precision.
double tolerance(const drivers::ProfileSignal& s, double v) {
  if (s.encoding.type == drivers::ValueType::f32) return std::abs(v) * 1e-6 + 1e-9;
  if (s.encoding.type == drivers::ValueType::boolean) return 0;
  return std::abs(s.encoding.scale) / 2 + 1e-9;
}

// Every signal of `table` (those `skip` names aside) has a value in `in`, none zero, no two alike.
template <class S, std::size_t N>
void expect_distinct_nonzero(const S& in, const drivers::SignalField<S> (&table)[N], std::set<std::string_view> skip = {}) {
  std::set<double> seen;
  for (const auto& f : table) {
    if (skip.count(f.signal)) continue;
    const auto v = drivers::number(in, f.member);
    ASSERT_TRUE(v) << f.signal << " has no value";
    EXPECT_NE(*v, 0) << f.signal;
    EXPECT_TRUE(seen.insert(*v).second) << f.signal << " = " << *v << " repeats another signal's value";
  }
}

// `read` equals `sent` in every signal of `table`, within what the profile's register carries.
template <class S, std::size_t N>
void expect_same(const S& sent, const S& read, const drivers::SignalField<S> (&table)[N],
                 const drivers::DeviceProfile& profile) {
  for (const auto& f : table) {
    const auto a = drivers::number(sent, f.member), b = drivers::number(read, f.member);
    ASSERT_EQ(a.has_value(), b.has_value()) << f.signal;
    if (!a) continue;
    const drivers::ProfileSignal* s = profile.find(f.signal);
    ASSERT_NE(s, nullptr) << f.signal;
    EXPECT_NEAR(*b, *a, tolerance(*s, *a)) << f.signal;
  }
}

// `read` has every array of `table` as `sent` has it (each value within what its register
// carries); an empty array reads empty (registers of zeros: no batches).
template <class S, std::size_t N>
void expect_same_arrays(const S& sent, const S& read, const drivers::ArrayField<S> (&table)[N],
                        const drivers::DeviceProfile& profile) {
  for (const auto& f : table) {
    const std::vector<double> a = drivers::numbers(sent, f.member), b = drivers::numbers(read, f.member);
    ASSERT_EQ(b.size(), a.size()) << f.signal;
    const drivers::ProfileSignal* s = profile.find(f.signal);
    ASSERT_NE(s, nullptr) << f.signal;
    for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(b[k], a[k], tolerance(*s, a[k])) << f.signal << "[" << k << "]";
  }
}

// B distinct values around `base` (B = the twin's firmware.window_batches).
std::vector<double> batches(double base) {
  std::vector<double> v;
  for (int k = 0; k < TwinConfig{}.firmware.window_batches; ++k) v.push_back(base + 0.125 * (k + 1));
  return v;
}

struct RoundTrip : ::testing::Test {
  std::vector<drivers::DeviceProfile> profiles = default_profiles();
  TwinService service{TwinConfig{}, profiles};
  TwinRegisterBus bus{service};
  TwinServiceClock clock{service};
  drivers::ProfileBench bench{bus, profiles[0], bus, profiles[1], bus, profiles[2], clock};

  void serve(const TwinSignals::Served& s) {
    service.locked([&](auto&, TwinSignals& signals, auto&) { signals.serve_fixed(s); });
  }
  // One window on all three devices, closed, so that their window results may be read.
  void run_window() {
    ASSERT_FALSE(bench.trigger().open_window(0.1));
    while (!bench.trigger().window_closed()) bench.clock().wait_until(clock.now_s() + 0.01);
  }

  static drivers::SynrmTelemetry synrm_telemetry() {
    drivers::SynrmTelemetry t;
    t.state = DriveState::stopping;
    t.fault = Fault::overtemperature;
    t.speed_rpm = 1234.5;
    t.im_A = 7.25;
    t.id_A = -3.5;
    t.iq_A = 6.125;
    t.ud_V = 111.5;
    t.uq_V = 222.25;
    t.udc_V = 456.7;
    t.pac_W = 3333.5;
    t.temp_C = 61.3;
    t.voltage_limited = true;
    t.pos_err_deg = 4.75;
    t.lock_lost = false;
    return t;
  }
  static drivers::SynrmWindow synrm_window() {
    drivers::SynrmWindow w;
    w.samples = 4321;
    w.fault = Fault::overspeed;
    w.window_s = 0.4321;
    w.speed_meas_rpm = 987.5;
    w.im_A = 5.5;
    w.id_A = -2.25;
    w.iq_A = 4.75;
    w.ud_V = 55.5;
    w.uq_V = 66.25;
    w.udc_V = 432.5;
    w.temp_C = 44.5;
    w.voltage_limited_fraction = 0.125;
    w.fallback_fraction = 0.375;
    w.lock_lost_fraction = 0.0625;
    w.pos_err_min_deg = -1.5;
    w.pos_err_mean_deg = 0.25;
    w.pos_err_max_deg = 2.5;
    w.speed_err_rpm = 3.75;
    w.ld_est_H = 0.0123;
    w.lq_est_H = 0.0456;
    w.rs_est_ohm = 0.789;
    w.batch_im_A = batches(5.0);
    w.batch_speed_meas_rpm = batches(980.0);
    return w;
  }
  static TwinSignals::Served served() {
    TwinSignals::Served s;
    s.synrm = synrm_telemetry();
    s.synrm_window = synrm_window();
    s.load.state = DriveState::stopping;
    s.load.fault = Fault::undervoltage;
    s.load.torque_Nm = 1.75;
    s.load.iq_A = 8.5;
    s.load_window.samples = 777;
    s.load_window.torque_Nm = 2.125;
    s.load_window.batch_torque_Nm = batches(1.5);
    s.meter_window.counts_m = 123456;
    s.meter_window.counts_g = 98765;
    s.meter_window.gate_s = 0.5;
    s.meter_window.idcm_A = 3.25;
    s.meter_window.idcg_A = -1.75;
    for (const double c : batches(12345)) s.meter_window.batch_counts_m.push_back(static_cast<std::uint64_t>(8 * c));
    for (const double c : batches(9876)) s.meter_window.batch_counts_g.push_back(static_cast<std::uint64_t>(8 * c));
    return s;
  }
};

TEST_F(RoundTrip, SynrmTelemetry) {
  // Position errors are read only with an estimator other than the encoder.
  ASSERT_FALSE(bench.synrm().set_estimator(drivers::Estimator::ekf_basic));
  TwinSignals::Served s = served();
  expect_distinct_nonzero(s.synrm, drivers::kSynrmTelemetrySignals, {"lock_lost"});
  serve(s);
  drivers::SynrmTelemetry t;
  ASSERT_FALSE(bench.synrm().read(t));
  expect_same(s.synrm, t, drivers::kSynrmTelemetrySignals, profiles[0]);
  EXPECT_EQ(t.fault_code_raw, std::nullopt);

  // On the lock guard the position error is not the estimator's: the drive leaves it empty.
  s.synrm.lock_lost = true;
  serve(s);
  ASSERT_FALSE(bench.synrm().read(t));
  s.synrm.pos_err_deg.reset();
  expect_same(s.synrm, t, drivers::kSynrmTelemetrySignals, profiles[0]);
}

TEST_F(RoundTrip, SynrmWindowWithItsEstimates) {
  ASSERT_FALSE(bench.synrm().set_estimator(drivers::Estimator::ekf_basic));
  TwinSignals::Served s = served();
  expect_distinct_nonzero(s.synrm_window, drivers::kSynrmWindowSignals);
  run_window();
  serve(s);
  drivers::SynrmWindow w;
  ASSERT_FALSE(bench.synrm().read_window(w));
  expect_same(s.synrm_window, w, drivers::kSynrmWindowSignals, profiles[0]);
  EXPECT_EQ(w.batch_im_A.size(), 10u);
  expect_same_arrays(s.synrm_window, w, drivers::kSynrmWindowArrays, profiles[0]);
  EXPECT_EQ(w.keeper, drivers::WindowKeeper::device);

  // A window without an Ld estimate says so (window_estimates_present): empty, not 0 H.
  s.synrm_window.ld_est_H.reset();
  run_window();
  serve(s);
  ASSERT_FALSE(bench.synrm().read_window(w));
  expect_same(s.synrm_window, w, drivers::kSynrmWindowSignals, profiles[0]);
}

TEST_F(RoundTrip, LoadTelemetryAndWindow) {
  const TwinSignals::Served s = served();
  expect_distinct_nonzero(s.load, drivers::kLoadTelemetrySignals);
  expect_distinct_nonzero(s.load_window, drivers::kLoadWindowSignals);
  run_window();
  serve(s);
  drivers::LoadTelemetry t;
  ASSERT_FALSE(bench.load().read(t));
  expect_same(s.load, t, drivers::kLoadTelemetrySignals, profiles[1]);
  drivers::LoadWindow w;
  ASSERT_FALSE(bench.load().read_window(w));
  expect_same(s.load_window, w, drivers::kLoadWindowSignals, profiles[1]);
  EXPECT_EQ(w.batch_torque_Nm.size(), 10u);
  expect_same_arrays(s.load_window, w, drivers::kLoadWindowArrays, profiles[1]);
}

// A window the device kept no batches of serves registers of zeros: the bench reads none.
TEST_F(RoundTrip, AWindowWithoutBatchesReadsNone) {
  TwinSignals::Served s = served();
  s.synrm_window.batch_im_A.clear();
  s.synrm_window.batch_speed_meas_rpm.clear();
  s.load_window.batch_torque_Nm.clear();
  s.meter_window.batch_counts_m.clear();
  s.meter_window.batch_counts_g.clear();
  run_window();
  serve(s);
  drivers::SynrmWindow w;
  ASSERT_FALSE(bench.synrm().read_window(w));
  EXPECT_TRUE(w.batch_im_A.empty());
  EXPECT_TRUE(w.batch_speed_meas_rpm.empty());
  EXPECT_EQ(w.im_A, 5.5);
  drivers::LoadWindow l;
  ASSERT_FALSE(bench.load().read_window(l));
  EXPECT_TRUE(l.batch_torque_Nm.empty());
  drivers::MeterReading m;
  ASSERT_FALSE(bench.meter().read(m));
  EXPECT_TRUE(m.batch_counts_m.empty());
  EXPECT_TRUE(m.batch_counts_g.empty());
}

TEST_F(RoundTrip, MeterGate) {
  const TwinSignals::Served s = served();
  expect_distinct_nonzero(s.meter_window, drivers::kMeterGateSignals);
  run_window();
  serve(s);
  drivers::MeterReading m;
  ASSERT_FALSE(bench.meter().read(m));
  expect_same(s.meter_window, m, drivers::kMeterGateSignals, profiles[2]);
  EXPECT_EQ(m.batch_counts_m.size(), 10u);
  expect_same_arrays(s.meter_window, m, drivers::kMeterGateArrays, profiles[2]);
  // The calibration the meter's registers hold comes with the reading.
  EXPECT_EQ(m.f0_Hz, TwinConfig{}.vfc.f0_Hz);
  EXPECT_EQ(m.kf_Hz_per_A, TwinConfig{}.vfc.kf_Hz_per_A);
}

// The twin's own values reach the bench too: with the fixed structs withdrawn, the registers
// show the firmware's telemetry again.
TEST_F(RoundTrip, WithdrawnFixedValuesGiveTheFirmwaresAgain) {
  serve(served());
  service.locked([](auto&, TwinSignals& signals, auto&) { signals.serve_fixed(std::nullopt); });
  drivers::SynrmTelemetry t;
  ASSERT_FALSE(bench.synrm().read(t));
  EXPECT_EQ(t.state, DriveState::disabled);
  EXPECT_EQ(t.speed_rpm, 0);
}

TEST(TwinSignalNames, ASignalTheTwinHasNoValueForIsRefusedNamingItAndTheDevice) {
  for (const std::size_t device : {0u, 1u, 2u}) {
    std::vector<drivers::DeviceProfile> profiles = default_profiles();
    // A profile built in code can name anything; a parsed one only the catalogue's signals.
    drivers::ProfileSignal odd = profiles[device].signals.back();
    odd.name = "window_flux_Wb";
    odd.address = 900;
    profiles[device].signals.push_back(odd);
    Twin twin{TwinConfig{}};
    try {
      TwinSignals signals(twin, profiles);
      ADD_FAILURE() << "accepted a profile with window_flux_Wb";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("window_flux_Wb"), std::string::npos) << what;
      EXPECT_NE(what.find(drivers::name(profiles[device].kind)), std::string::npos) << what;
      EXPECT_NE(what.find(profiles[device].name), std::string::npos) << what;
    }
  }
}

// Every signal of the catalogue, of every kind and meter kind, is one the twin serves: any
// profile the parser accepts can be emulated.
TEST(TwinSignalNames, TheTwinServesEveryCatalogueSignal) {
  for (const drivers::DeviceKind kind : drivers::kDeviceKinds) {
    std::vector<drivers::DeviceProfile> profiles = default_profiles();
    drivers::DeviceProfile& p = profiles[static_cast<std::size_t>(kind)];
    std::uint16_t address = 1000;
    for (const drivers::SignalSpec& spec : drivers::signal_catalogue(kind)) {
      if (p.find(spec.name)) continue;
      drivers::ProfileSignal s;
      s.name = std::string(spec.name);
      s.role = spec.role;
      s.kind = drivers::RegisterKind::input;
      s.address = address;
      if (spec.array) s.count = static_cast<std::uint8_t>(TwinConfig{}.firmware.window_batches);
      address = static_cast<std::uint16_t>(s.last_address() + 1);
      p.signals.push_back(s);
    }
    Twin twin{TwinConfig{}};
    EXPECT_NO_THROW((TwinSignals{twin, profiles})) << drivers::name(kind);
  }
}

}  // namespace
}  // namespace synbench::emulator
