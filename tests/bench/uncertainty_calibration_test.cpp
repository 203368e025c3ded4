// The reported type A against the truth of repetition: the thesis point (700 rpm, 2.5 N m,
// 56 deg, encoder, CAPWM) on the in-process twin under 30 noise seeds. The scatter of the
// record's pdcm_W, pm_W and im_A over the seeds against the mean type A the records report
// (their `_repeat` parts), and against the naive per-sample s / sqrt(N) from the same windows.
// I_m agrees; the powers' batch estimate is found conservative (see below), never optimistic.
//
// One run per seed: the twin keeps one batch per control period (B = N, per sample); the
// devices are wrapped so the procedure sees those merged into the bench's B = 10 batches (sums
// of equal consecutive runs: exactly what a 10-batch twin reports), so the record's values are
// the estimator under test and the per-sample batches give the naive estimate of the same window.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <vector>

#include "bench/point_procedure.hpp"
#include "bench/uncertainty.hpp"
#include "emulator/twin_bench.hpp"

namespace synbench::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kSeeds = 30;
constexpr int kBatches = 10;

template <class T>
std::vector<T> merge(const std::vector<T>& v, std::size_t into, bool mean) {
  if (v.size() < into || v.size() % into) return v;
  const std::size_t k = v.size() / into;
  std::vector<T> out;
  for (std::size_t i = 0; i < into; ++i) {
    T s = std::accumulate(v.begin() + static_cast<std::ptrdiff_t>(i * k),
                          v.begin() + static_cast<std::ptrdiff_t>((i + 1) * k), T{});
    out.push_back(mean ? s / static_cast<T>(k) : s);
  }
  return out;
}

// The three devices' windows, kept raw and handed on merged to kBatches.
struct Raw {
  drivers::SynrmWindow w;
  drivers::LoadWindow lw;
  drivers::MeterReading m;
};

class MergingSynrm : public drivers::SynrmDrive {
 public:
  MergingSynrm(drivers::SynrmDrive& in, Raw& raw) : in_(in), raw_(raw) {}
  std::error_code enable(bool on) override { return in_.enable(on); }
  std::error_code set_speed_rpm(double v) override { return in_.set_speed_rpm(v); }
  std::error_code set_angle_deg(double v) override { return in_.set_angle_deg(v); }
  std::error_code set_pwm(drivers::Pwm v) override { return in_.set_pwm(v); }
  std::error_code set_estimator(drivers::Estimator v) override { return in_.set_estimator(v); }
  std::error_code reset_fault() override { return in_.reset_fault(); }
  std::error_code read(drivers::SynrmTelemetry& out) override { return in_.read(out); }
  std::error_code read_window(drivers::SynrmWindow& out) override {
    if (auto ec = in_.read_window(out)) return ec;
    raw_.w = out;
    out.batch_im_A = merge(out.batch_im_A, kBatches, true);
    out.batch_speed_meas_rpm = merge(out.batch_speed_meas_rpm, kBatches, true);
    return {};
  }

 private:
  drivers::SynrmDrive& in_;
  Raw& raw_;
};

class MergingLoad : public drivers::LoadDrive {
 public:
  MergingLoad(drivers::LoadDrive& in, Raw& raw) : in_(in), raw_(raw) {}
  std::error_code enable(bool on) override { return in_.enable(on); }
  std::error_code set_torque_Nm(double v) override { return in_.set_torque_Nm(v); }
  std::error_code reset_fault() override { return in_.reset_fault(); }
  std::error_code read(drivers::LoadTelemetry& out) override { return in_.read(out); }
  std::error_code read_window(drivers::LoadWindow& out) override {
    if (auto ec = in_.read_window(out)) return ec;
    raw_.lw = out;
    out.batch_torque_Nm = merge(out.batch_torque_Nm, kBatches, true);
    return {};
  }

 private:
  drivers::LoadDrive& in_;
  Raw& raw_;
};

class MergingMeter : public drivers::PowerMeter {
 public:
  MergingMeter(drivers::PowerMeter& in, Raw& raw) : in_(in), raw_(raw) {}
  std::error_code read(drivers::MeterReading& out) override {
    if (auto ec = in_.read(out)) return ec;
    raw_.m = out;
    out.batch_counts_m = merge(out.batch_counts_m, kBatches, false);
    out.batch_counts_g = merge(out.batch_counts_g, kBatches, false);
    return {};
  }

 private:
  drivers::PowerMeter& in_;
  Raw& raw_;
};

double sd(const std::vector<double>& x) {
  const double m = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(x.size());
  double ss = 0;
  for (double v : x) ss += (v - m) * (v - m);
  return std::sqrt(ss / static_cast<double>(x.size() - 1));
}

double rms(const std::vector<double>& x) {
  double ss = 0;
  for (double v : x) ss += v * v;
  return std::sqrt(ss / static_cast<double>(x.size()));
}

TEST(UncertaintyCalibration, ReportedTypeAMatchesTheScatterOverNoiseSeeds) {
  std::vector<double> pdcm, pm, im, u_pdcm, u_pm, u_im, n_pdcm, n_pm, n_im;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    emulator::TwinConfig c;
    c.sim.seed_int = seed;
    c.firmware.window_batches = 10000;  // one batch per 100 us control period of the 1 s window
    emulator::TwinBench bench{c};
    Raw raw;
    auto dev = bench.devices();
    MergingSynrm s(*dev.synrm, raw);
    MergingLoad l(*dev.load, raw);
    MergingMeter m(*dev.meter, raw);
    dev.synrm = &s;
    dev.load = &l;
    dev.meter = &m;
    PointRequest req;
    req.speed_rpm = 700;
    req.load_Nm = 2.5;
    req.angle_deg = 56;
    // A real window starts at whatever rotor angle the bench happens to reach it at; the twin's
    // seeds change only the noise, so each seed ramps its load a little slower (up to 7 %, the
    // 1.25 s ramp up to 85 ms longer), spreading the window's start over a revolution.
    PointOptions opt;
    opt.load_ramp_Nm_per_s /= 1.0 + 0.07 * (seed - 1) / kSeeds;
    const auto p = run_point(dev, bench.clock(), req, opt);
    ASSERT_TRUE(p.has_record()) << "seed " << seed << ": " << p.error();
    ASSERT_EQ(raw.w.batch_im_A.size(), 10000u) << "the twin keeps a batch per control period";
    const auto& r = p.record();
    ASSERT_TRUE(r.pdcm_u_repeat_W && r.im_u_repeat_A && p.budget()->u_repeat(Output::pm_W));
    pdcm.push_back(r.pdcm_W);
    pm.push_back(r.pm_W);
    im.push_back(r.im_A);
    u_pdcm.push_back(*r.pdcm_u_repeat_W);
    u_pm.push_back(*p.budget()->u_repeat(Output::pm_W));
    u_im.push_back(*r.im_u_repeat_A);
    // The naive estimate: every sample an independent observation, s / sqrt(N).
    const double wm = r.speed_meas_rpm * 2 * kPi / 60;
    const auto i_m = batch_currents_A(raw.m.batch_counts_m, raw.m.gate_s, raw.m.f0_Hz, raw.m.kf_Hz_per_A);
    n_pdcm.push_back(r.udc_V * type_a_of_mean(i_m).value_or(0));
    n_pm.push_back(std::hypot(wm * type_a_of_mean(raw.lw.batch_torque_Nm).value_or(0),
                              (r.load_Nm + 2 * 2e-4 * wm) * 2 * kPi / 60 *
                                  type_a_of_mean(raw.w.batch_speed_meas_rpm).value_or(0)));
    n_im.push_back(type_a_of_mean(raw.w.batch_im_A).value_or(0));
  }
  // The band. With independent normal results, (n - 1) s^2 / sigma^2 is chi-square with n - 1 =
  // 29 degrees of freedom: its 0.5 % and 99.5 % points are 13.12 and 52.34, so the observed SD
  // lies within [sqrt(13.12 / 29), sqrt(52.34 / 29)] = [0.673, 1.343] sigma in 99 % of runs
  // (99 %, not 95 %: three quantities are tested, and a seed set is fixed, so a tight band would
  // only test that set's luck). The reported type A is itself an estimate: each from B = 10
  // batches (9 degrees of freedom), its RMS over 30 points has 270, a relative SD of
  // 1 / sqrt(2 x 270) = 4.3 %, 3 x that 13 %. The band on observed / reported: [0.673 / 1.13,
  // 1.343 / 0.87] = [0.60, 1.54].
  constexpr double lo = 0.60, hi = 1.54;
  struct Row {
    const char* name;
    double obs, rep, naive;
  };
  const Row rows[] = {{"pdcm_W", sd(pdcm), rms(u_pdcm), rms(n_pdcm)},
                      {"pm_W", sd(pm), rms(u_pm), rms(n_pm)},
                      {"im_A", sd(im), rms(u_im), rms(n_im)}};
  for (const auto& row : rows)
    std::printf("%-7s observed SD %.4g, mean reported type A (RMS) %.4g, ratio %.3f; naive s/sqrt(N) %.4g, ratio %.3f\n",
                row.name, row.obs, row.rep, row.obs / row.rep, row.naive, row.obs / row.naive);
  // I_m: the reported type A agrees with the seeds' scatter.
  EXPECT_GE(rows[2].obs / rows[2].rep, lo);
  EXPECT_LE(rows[2].obs / rows[2].rep, hi);
  // P_dcM and P_m: the reported type A is conservative, 2 to 3 times the seeds' scatter
  // (docs/uncertainty.md, "Calibration on the twin"): the speed loop (3 Hz) and the load's
  // current loop pin the window's mean (integral action), so consecutive 0.1 s batches are
  // anticorrelated and their scatter overstates the mean's. It never understates it.
  for (const auto& row : {rows[0], rows[1]}) {
    EXPECT_LE(row.obs / row.rep, hi) << row.name;
    EXPECT_GT(row.obs / row.rep, 0.25) << row.name << ": more than 4 times conservative";
  }
  // The naive per-sample estimate from the same windows fails the band for both powers (here by
  // overstating: the loops' integral action makes the samples anticorrelated).
  for (const auto& row : {rows[0], rows[1]}) {
    const double ratio = row.obs / row.naive;
    EXPECT_TRUE(ratio < lo || ratio > hi) << row.name << ": naive ratio " << ratio;
  }
}

}  // namespace
}  // namespace synbench::bench
