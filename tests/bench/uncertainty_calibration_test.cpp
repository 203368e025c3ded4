// The reported type A against the truth of repetition: the thesis point (700 rpm, 2.5 N m,
// 56 deg, encoder, CAPWM) and points of other character on the in-process twin, each under 30
// noise seeds. The scatter of the record's pdcm_W, pm_W, im_A and speed_meas_rpm over the seeds
// against the RMS of the type A the records report (their `_repeat` parts: the lag-1 batch
// estimator, the speed's position bridge), against
// the plain s / sqrt(B) of the same 10 batches, the regrouping fit of V(B) = a + b B over
// B = 10, 5, 2, and the naive per-sample s / sqrt(N) (docs/uncertainty.md, "Calibration on the
// twin").
//
// One run per seed: the twin keeps one batch per control period (B = N, per sample); the
// devices are wrapped so the procedure sees those merged into the bench's B = 10 batches (sums
// of equal consecutive runs: exactly what a 10-batch twin reports), so the record's values are
// the estimator under test and the per-sample batches give the naive estimate of the same window.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
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

// The repeat part of `o` with every type A component replaced by `type_a(name)`.
template <class F>
double repeat_with(const PointBudget& b, Output o, F&& type_a) {
  double ss = 0;
  for (const auto& c : b.components) {
    const double sens = c.sensitivity[static_cast<std::size_t>(o)];
    if (sens == 0 || !c.repeat) continue;
    const double u = c.type == 'A' ? type_a(c.name) : c.u.value_or(0);
    ss += sens * sens * u * u;
  }
  return std::sqrt(ss);
}

// One quantity over the seeds: the results and four estimates of their SD per seed.
struct Series {
  std::vector<double> value, lag1, plain, regroup, naive;
};
struct Row {
  const char* name;
  double obs, lag1, lag1_spread, plain, plain_spread, regroup, regroup_spread, naive;
};

double spread(const std::vector<double>& u) { return sd(u) / rms(u); }  // SD over seeds / RMS

std::vector<Row> calibrate(double speed_rpm, double load_Nm, double angle_deg) {
  Series s[4];
  for (int seed = 1; seed <= kSeeds; ++seed) {
    emulator::TwinConfig c;
    c.sim.seed_int = seed;
    c.firmware.window_batches = 10000;  // one batch per 100 us control period of the 1 s window
    emulator::TwinBench bench{c};
    Raw raw;
    auto dev = bench.devices();
    MergingSynrm sy(*dev.synrm, raw);
    MergingLoad l(*dev.load, raw);
    MergingMeter m(*dev.meter, raw);
    dev.synrm = &sy;
    dev.load = &l;
    dev.meter = &m;
    PointRequest req;
    req.speed_rpm = speed_rpm;
    req.load_Nm = load_Nm;
    req.angle_deg = angle_deg;
    // A real window starts at whatever rotor angle the bench happens to reach it at; the twin's
    // seeds change only the noise, so each seed ramps its load a little slower (up to 7 %),
    // spreading the window's start over a revolution.
    PointOptions opt;
    opt.load_ramp_Nm_per_s /= 1.0 + 0.07 * (seed - 1) / kSeeds;
    const auto p = run_point(dev, bench.clock(), req, opt);
    EXPECT_TRUE(p.has_record()) << "seed " << seed << ": " << p.error();
    if (!p.has_record()) return {};
    EXPECT_EQ(raw.w.batch_im_A.size(), 10000u) << "the twin keeps a batch per control period";
    const auto& r = p.record();
    const PointBudget* b = p.budget() ? &*p.budget() : nullptr;
    EXPECT_TRUE(b && r.pdcm_u_repeat_W && r.im_u_repeat_A && b->u_repeat(Output::pm_W));
    if (!b || !r.pdcm_u_repeat_W || !r.im_u_repeat_A || !b->u_repeat(Output::pm_W)) return {};
    // The devices' 10 batches, as the procedure saw them, and the per-sample ones.
    const auto i_m1 = batch_currents_A(raw.m.batch_counts_m, raw.m.gate_s, raw.m.f0_Hz, raw.m.kf_Hz_per_A);
    const auto i_m10 = batch_currents_A(merge(raw.m.batch_counts_m, kBatches, false), raw.m.gate_s, raw.m.f0_Hz,
                                        raw.m.kf_Hz_per_A);
    const auto t10 = merge(raw.lw.batch_torque_Nm, kBatches, true);
    const auto n10 = merge(raw.w.batch_speed_meas_rpm, kBatches, true);
    const auto im10 = merge(raw.w.batch_im_A, kBatches, true);
    auto batches = [&](const std::string& name) -> const std::vector<double>& {
      static const std::vector<double> none;
      return name == "I_dcM type A" ? i_m10 : name == "T_L type A" ? t10 : name == "speed type A" ? n10
                                                                     : name == "I_m type A"     ? im10
                                                                                                 : none;
    };
    auto plain = [&](const std::string& n) { return batch_standard_error(batches(n)).value_or(0); };
    auto regroup = [&](const std::string& n) { return batches(n).empty() ? 0.0 : *regrouped_type_a(batches(n)); };
    const double wm = r.speed_meas_rpm * 2 * kPi / 60;
    // The speed: its own component (a position bridge, not batch means: docs/uncertainty.md).
    double u_speed = -1;
    for (const auto& comp : b->components)
      if (comp.name == "speed type A" && comp.u) u_speed = *comp.u;
    EXPECT_GE(u_speed, 0) << "the budget has the speed's type A";
    const double naive[4] = {
        r.udc_V * batch_standard_error(i_m1).value_or(0),
        std::hypot(wm * batch_standard_error(raw.lw.batch_torque_Nm).value_or(0),
                   (r.load_Nm + 2 * 2e-4 * wm) * 2 * kPi / 60 * batch_standard_error(raw.w.batch_speed_meas_rpm).value_or(0)),
        batch_standard_error(raw.w.batch_im_A).value_or(0),
        batch_standard_error(raw.w.batch_speed_meas_rpm).value_or(0)};
    const double value[4] = {r.pdcm_W, r.pm_W, r.im_A, r.speed_meas_rpm};
    const double lag1[4] = {*r.pdcm_u_repeat_W, *b->u_repeat(Output::pm_W), *r.im_u_repeat_A, u_speed};
    const Output out[3] = {Output::pdcm_W, Output::pm_W, Output::im_A};
    for (int q = 0; q < 4; ++q) {
      s[q].value.push_back(value[q]);
      s[q].lag1.push_back(lag1[q]);
      s[q].plain.push_back(q < 3 ? repeat_with(*b, out[q], plain) : plain("speed type A"));
      s[q].regroup.push_back(q < 3 ? repeat_with(*b, out[q], regroup) : regroup("speed type A"));
      s[q].naive.push_back(naive[q]);
    }
  }
  std::vector<Row> rows;
  const char* names[4] = {"pdcm_W", "pm_W", "im_A", "speed_meas_rpm"};
  std::printf("%g rpm, %g N m, %g deg, %d seeds\n", speed_rpm, load_Nm, angle_deg, kSeeds);
  for (int q = 0; q < 4; ++q) {
    const Row row{names[q],          sd(s[q].value),        rms(s[q].lag1),    spread(s[q].lag1),
                  rms(s[q].plain),   spread(s[q].plain),    rms(s[q].regroup), spread(s[q].regroup),
                  rms(s[q].naive)};
    std::printf(
        "  %-7s observed SD %.4g | reported %.4g ratio %.3f spread %.2f | s/sqrt(B) %.4g ratio %.3f spread %.2f"
        " | regroup %.4g ratio %.3f spread %.2f | naive %.4g ratio %.3f\n",
        row.name, row.obs, row.lag1, row.obs / row.lag1, row.lag1_spread, row.plain, row.obs / row.plain,
        row.plain_spread, row.regroup, row.obs / row.regroup, row.regroup_spread, row.naive, row.obs / row.naive);
    rows.push_back(row);
  }
  return rows;
}

// The band. With independent normal results, (n - 1) s^2 / sigma^2 is chi-square with n - 1 =
// 29 degrees of freedom: its 0.5 % and 99.5 % points are 13.12 and 52.34, so the observed SD lies
// within [sqrt(13.12 / 29), sqrt(52.34 / 29)] = [0.673, 1.343] sigma in 99 % of runs (99 %, not
// 95 %: several quantities are tested, and a seed set is fixed). The reported type A is itself an
// estimate: its RMS over the 30 points has about the relative SD spread / sqrt(30) (spread: the
// SD of the per-point u over its RMS, printed; at most kMaxSpread, asserted), 3 x that at most
// 3 x 0.45 / sqrt(30) = 25 %. The band on observed / RMS reported: [0.673 / 1.25, 1.343 / 0.75]
// = [0.54, 1.78]; wider than the plain estimator's [0.60, 1.54] because the lag-1 estimate from
// 10 batches is noisier (spread about 0.4 against 0.25).
constexpr double kMaxSpread = 0.45;
const double kLo = 0.673 / (1 + 3 * kMaxSpread / std::sqrt(30.0));
const double kHi = 1.343 / (1 - 3 * kMaxSpread / std::sqrt(30.0));

const Row& find(const std::vector<Row>& rows, const char* name) {
  for (const auto& r : rows)
    if (std::string(r.name) == name) return r;
  static const Row none{};
  ADD_FAILURE() << "no row " << name;
  return none;
}

// The reported (lag-1) type A agrees with the seeds' scatter, and its per-point spread is within
// what the band allows.
void expect_agreement(const Row& row) {
  EXPECT_GE(row.obs / row.lag1, kLo) << row.name << ": the reported type A overstates the scatter";
  EXPECT_LE(row.obs / row.lag1, kHi) << row.name << ": the reported type A understates the scatter";
  EXPECT_LE(row.lag1_spread, kMaxSpread) << row.name << ": the per-point estimate is noisier than the band allows";
}

void expect_calibrated(const std::vector<Row>& rows) {
  ASSERT_EQ(rows.size(), 4u);
  const Row &pdcm = find(rows, "pdcm_W"), &pm = find(rows, "pm_W"), &im = find(rows, "im_A"),
            &speed = find(rows, "speed_meas_rpm");
  expect_agreement(pdcm);
  expect_agreement(im);
  expect_agreement(pm);
  // The speed alone: its batch means scatter far more than the window's mean speed does (the
  // speed loop's integral action cancels them over the window), so their s / sqrt(B) overstates
  // it 4 to 7 times. The position bridge agrees at 300 rpm and stays conservative, never
  // optimistic, at 700 and 1200 rpm (ratio 0.48 and 0.26): the speed ripple at the rotation's
  // harmonics is counted in the position error at the batch ends, while a 1 s window spans
  // (nearly) whole revolutions and cancels it. Its share of u(P_m) is then small enough that
  // P_m agrees (above).
  EXPECT_LE(speed.obs / speed.lag1, kHi) << "the speed's bridge understates the scatter";
  EXPECT_GT(speed.obs / speed.lag1, 0.2) << "the speed's bridge more than 5 times conservative";
  EXPECT_LE(speed.lag1_spread, kMaxSpread);
  EXPECT_LT(speed.obs / speed.plain, speed.obs / speed.lag1) << "the bridge is closer than s / sqrt(B)";
  // The plain s / sqrt(B) of the same batches fails the band for P_dcM (by overstating): the
  // lag-1 model is what brings it in.
  EXPECT_LT(pdcm.obs / pdcm.plain, kLo) << "plain s / sqrt(B) of P_dcM";
  // The naive per-sample estimate from the same windows fails it for both powers (by
  // overstating: the loops' integral action makes the samples anticorrelated).
  for (const Row* row : {&pdcm, &pm}) {
    const double ratio = row->obs / row->naive;
    EXPECT_TRUE(ratio < kLo || ratio > kHi) << row->name << ": naive ratio " << ratio;
  }
}

TEST(UncertaintyCalibration, TheThesisPointsTypeAAgreesWithTheScatterOverNoiseSeeds) {
  expect_calibrated(calibrate(700, 2.5, 56));
}

TEST(UncertaintyCalibration, ASlowLightPointsTypeAAgreesWithTheScatterOverNoiseSeeds) {
  expect_calibrated(calibrate(300, 1.5, 48));
}

TEST(UncertaintyCalibration, AFastHeavyPointsTypeAAgreesWithTheScatterOverNoiseSeeds) {
  expect_calibrated(calibrate(1200, 3.0, 60));
}

}  // namespace
}  // namespace synbench::bench
