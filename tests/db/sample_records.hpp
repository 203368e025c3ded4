// Deterministic point records for the db tests and the crash child: every field set, awkward
// doubles (-0.0, subnormals, extremes, values without a short decimal form), nulls, truth and
// faults on some indices, so a round trip that loses anything shows.
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>

#include "drivers/json.hpp"
#include <stdlib.h>

#include "bench/point_record.hpp"

namespace synbench::db::testing {

inline bench::PointRecord sample_record(std::int64_t i) {
  const double x = static_cast<double>(i);
  bench::PointRecord r;
  r.speed_rpm = 250.0 * static_cast<double>(i % 7);
  r.load_Nm = x / 3.0;                                   // no short decimal form
  r.angle_deg = i % 11 == 0 ? -0.0 : 45.0 + 0.1 * x;     // sign of zero must survive
  r.estimator = static_cast<drivers::Estimator>(i % 7);
  r.pwm = static_cast<drivers::Pwm>(i % 2);
  r.speed_meas_rpm = r.speed_rpm + 1e-9 * x;
  r.im_A = std::sqrt(2.0) * (1 + x);
  r.id_A = std::cos(x);
  r.iq_A = std::sin(x);
  if (i % 13 != 12) r.angle_meas_deg = i % 2 == 0 ? 45.0 + 1e-7 * x : 90.0 - 1.0 / (3.0 + x);  // null on some
  r.angle_off = i % 8 == 6;
  if (i % 9 != 4) {  // null on some
    r.im_u_A = 1e-4 * (1 + x);
    r.im_u_repeat_A = 1e-5 / (1 + x);
    r.pdcm_u_W = 0.1 * x + 1.0 / 3.0;
    r.pdcm_u_repeat_W = 0.01 + 1e-12 * x;
    r.pdcg_u_W = 0.2 + x;
    r.pm_u_W = 3e-3 * (2 + x);
    r.efficiency_u = 1e-3 / (3 + x);
    r.efficiency_u_repeat = 1e-5 * (5 + x);
  }
  r.ud_V = -std::numeric_limits<double>::denorm_min() * static_cast<double>(i % 3);  // subnormal
  r.uq_V = 1e-300 * x;
  r.udc_V = 565.0 + std::nextafter(0.0, 1.0) * x;
  r.idcm_A = 0.1 + 0.2;
  r.idcg_A = std::numeric_limits<double>::max() / (2.0 + x);
  r.pdcm_W = r.udc_V * r.idcm_A;
  r.pdcg_W = r.udc_V * r.idcg_A;
  r.pm_W = 1.0 / 7.0 * x;
  r.efficiency = r.pdcm_W != 0 ? r.pm_W / r.pdcm_W : 0;
  if (r.estimator != drivers::Estimator::encoder) {
    r.pos_err_min_deg = -1.0 - x / 1000.0;
    r.pos_err_mean_deg = std::numeric_limits<double>::epsilon() * x;
    r.pos_err_max_deg = 1.0 + x / 999.0;
    r.speed_err_rpm = -0.0;
    if (i % 2 == 0) {  // parameter estimates only for some estimators; nulls elsewhere
      r.ld_est_H = 0.045 + 1e-6 * x;
      r.lq_est_H = 0.012 - 1e-7 * x;
      r.rs_est_ohm = 2.4;
      r.ld_err_pct = 3.3333333333333335;
      r.lq_err_pct = -1.25;
      r.rs_err_pct = 12.5 / (1 + x);
    }
  }
  r.temp_C = 40.0 + x / 17.0;
  r.window_s = 0.5;
  r.samples = 5000 + static_cast<std::uint32_t>(i % 1000);
  r.settle_s = 1.0 / (1 + x);
  r.voltage_limited = i % 4 == 1;
  r.unstable = i % 6 == 5;
  r.below_min_speed = i % 5 == 2;
  r.fallback_fraction = r.below_min_speed ? 1.0 - 1.0 / (3.0 + x) : 0.0;
  r.lock_lost = i % 7 == 4;
  r.window_source = i % 9 == 7 ? drivers::WindowKeeper::host : drivers::WindowKeeper::device;
  if (i % 5 == 3) r.fault = i % 10 == 3 ? "overcurrent" : "link_loss, \"quoted\"";  // CSV quoting
  if (i % 10 == 9) {
    r.fault = "unknown";  // a device code without a label, kept as the device sent it
    r.fault_code_raw = i == 9 ? 4'294'967'295 : 0x2310 + i;
  }
  if (i % 3 != 0) {
    drivers::TruthWindow t;
    t.pin_W = 300.0 + x / 3.0;
    t.pcu_W = 12.0 + 1e-12 * x;
    t.pfe_W = -0.0;
    t.pmech_W = 1.5e-310;  // subnormal
    t.pinvm_W = std::numeric_limits<double>::lowest() / 2;
    t.pm_W = 250.0 + 0.1 * x;
    t.temp_C = 40.0 + x / 13.0;
    r.truth = t;
  }
  return r;
}

// Exact equality: nlohmann writes every double in its shortest round-trip form and keeps the sign
// of zero, so equal text means equal bits for every field (NaN aside, which these samples avoid).
inline std::string exact_text(const bench::PointRecord& r) { return bench::to_json(r).dump(); }

// A fresh directory under the system's temp directory (TMPDIR), removed with its files.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "synbench-db-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

}  // namespace synbench::db::testing
