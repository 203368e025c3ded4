// The point's uncertainty budget: its components and their propagation (GUM 5.1.2).
#include "bench/uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace synbench::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadPerRpm = 2.0 * kPi / 60.0;

constexpr std::size_t idx(Output o) { return static_cast<std::size_t>(o); }

// A type A component from batch means by `estimate` (which needs `min_batches` of them), or
// unavailable with the reason.
BudgetComponent type_a(std::string name, std::string source, std::string unit, const std::vector<double>& batches,
                       const char* device, std::optional<double> (*estimate)(std::span<const double>) = type_a_of_mean,
                       std::size_t min_batches = 2) {
  BudgetComponent c;
  c.name = std::move(name);
  c.type = 'A';
  c.source = std::move(source);
  c.unit = std::move(unit);
  c.repeat = true;
  c.u = estimate(batches);
  if (!c.u)
    c.why = batches.empty() ? std::string(device) + " reports no batch means"
                            : std::string(device) + " reports fewer than " + std::to_string(min_batches) + " batch means";
  return c;
}

BudgetComponent type_b(std::string name, std::string source, std::string unit, double u, bool repeat = false) {
  BudgetComponent c;
  c.name = std::move(name);
  c.type = 'B';
  c.source = std::move(source);
  c.unit = std::move(unit);
  c.u = u;
  c.repeat = repeat;
  return c;
}

// A VFC channel's components, entering `out` through the current with sensitivity `c_I`.
void vfc_channel(std::vector<BudgetComponent>& comps, const char* ch, const drivers::MeterReading& m, double I_A,
                 const drivers::UncertaintyConfig& cfg, Output out, double c_I) {
  const std::string tag = std::string(" (") + ch + ")";
  const auto& counts = std::string(ch) == "M" ? m.batch_counts_m : m.batch_counts_g;
  const bool vfc = m.kf_Hz_per_A > 0 && m.gate_s > 0;
  std::vector<BudgetComponent> add;
  auto a = type_a(std::string("I_dc") + ch + " type A", "VFC sub-gates' means, lag-1 (MA(1)) model, GUM 4.2.3", "A",
                  vfc ? batch_currents_A(counts, m.gate_s, m.f0_Hz, m.kf_Hz_per_A) : std::vector<double>{},
                  vfc ? "the meter" : "the meter (no VFC calibration reported)");
  add.push_back(std::move(a));
  if (vfc) {
    const double kf = m.kf_Hz_per_A, tg = m.gate_s;
    // Start and end phase of the gate each uniform over one count: triangular, 1 / sqrt 6 count.
    add.push_back(type_b("VFC count quantisation" + tag, "physics.md Sec. 4 (triangular, 1 count / sqrt 6)", "A",
                         1.0 / (std::sqrt(6.0) * kf * tg), /*repeat=*/true));
    // dI/dT_g = -N / (Kf T_g^2) = -(f0 + Kf I) / (Kf T_g): a relative clock error d acts as an
    // offset of (f0 / Kf + I) d, f0 / Kf = 5 A dominating the 0 to 2 A being measured.
    add.push_back(type_b("meter clock (gate time)" + tag, "[assumed] crystal, ppm", "A",
                         (m.f0_Hz / kf + std::abs(I_A)) * cfg.meter_clock_u_ppm * 1e-6));
    add.push_back(type_b("VFC f0 calibration" + tag, "[assumed] f0 after zero-current calibration", "A",
                         cfg.vfc_f0_u_Hz / kf));
    add.push_back(type_b("VFC Kf calibration" + tag, "[assumed] gain calibration, %", "A",
                         std::abs(I_A) * cfg.vfc_kf_u_pct / 100.0));
  }
  add.push_back(type_b("DC current sensor gain" + tag, "[assumed] sensor gain, %", "A",
                       std::abs(I_A) * cfg.dc_sensor_gain_u_pct / 100.0));
  add.push_back(type_b("DC current sensor offset" + tag, "[assumed] sensor offset", "A", cfg.dc_sensor_offset_u_A));
  for (auto& c : add) {
    c.sensitivity[idx(out)] = c_I;
    comps.push_back(std::move(c));
  }
}

}  // namespace

std::optional<double> batch_standard_error(std::span<const double> batch_means) {
  const std::size_t b = batch_means.size();
  if (b < 2) return std::nullopt;
  double mean = 0;
  for (double x : batch_means) mean += x;
  mean /= static_cast<double>(b);
  double ss = 0;
  for (double x : batch_means) ss += (x - mean) * (x - mean);
  const double s = std::sqrt(ss / static_cast<double>(b - 1));
  return s / std::sqrt(static_cast<double>(b));
}

std::optional<BatchTypeA> batch_type_a(std::span<const double> batch_means) {
  const auto se = batch_standard_error(batch_means);
  if (!se) return std::nullopt;
  BatchTypeA r;
  r.u = r.standard_error = *se;
  const std::size_t n = batch_means.size();
  // Below 4 batches the lag-1 sum carries no information beyond the lag-0 one (B = 2: it is
  // exactly -Q0 / 2) or its estimate of gamma0 can turn negative (B = 3).
  if (n < 4) return r;
  const double B = static_cast<double>(n);
  double mean = 0;
  for (double x : batch_means) mean += x;
  mean /= B;
  double q0 = 0, q1 = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double y = batch_means[k] - mean;
    q0 += y * y;
    if (k + 1 < n) q1 += y * (batch_means[k + 1] - mean);
  }
  // E[Q0] = a00 g0 + a01 g1 and E[Q1] = a10 g0 + a11 g1 for an MA(1) series with lag-0 and
  // lag-1 autocovariances g0, g1: tr(C S) and tr(C M C S) with C the centring matrix, S the
  // series' covariance and M the symmetric lag-1 pair matrix (docs/uncertainty.md).
  const double a00 = B - 1, a01 = -2 * (B - 1) / B;
  const double a10 = -(B - 1) / B, a11 = (B - 1) - 2 * (2 * B - 3) / B + 2 * (B - 1) * (B - 1) / (B * B);
  const double det = a00 * a11 - a01 * a10;
  // For B >= 4, |Q1| <= Q0 and a11 > |a01| keep g0 positive whenever Q0 is.
  const double g0 = (a11 * q0 - a01 * q1) / det;
  double g1 = (a00 * q1 - a10 * q0) / det;
  if (!(g0 > 0)) return r;  // constant batches: u = 0 already
  r.lag1 = true;
  // sw^2 = tau (g0 + 2 g1) >= 0; g1 <= g0 / 2 keeps the MA(1) covariance positive definite.
  g1 = std::clamp(g1, -g0 / 2, g0 / 2);
  r.lag1_correlation = g1 / g0;
  const double var = (g0 + 2 * g1) / B - 2 * g1 / (B * B);
  // gamma1 > 0 is outside the stored-energy model (it gives gamma1 <= 0): positively correlated
  // batches. The same MA(1) formula then inflates; never report less than s / sqrt(B) there.
  r.u = g1 > 0 ? std::max(std::sqrt(var), *se) : std::sqrt(var);
  return r;
}

std::optional<double> regrouped_type_a(std::span<const double> batch_means) {
  const auto se = batch_standard_error(batch_means);
  if (!se) return std::nullopt;
  const std::size_t n = batch_means.size();
  std::vector<double> g, v;
  for (std::size_t groups = n; groups >= 2; --groups) {
    if (n % groups) continue;
    const std::size_t k = n / groups;
    std::vector<double> m(groups, 0.0);
    for (std::size_t i = 0; i < n; ++i) m[i / k] += batch_means[i] / static_cast<double>(k);
    const double e = *batch_standard_error(m);
    g.push_back(static_cast<double>(groups));
    v.push_back(e * e);
  }
  if (g.size() < 2) return se;
  const double cnt = static_cast<double>(g.size());
  double sg = 0, sv = 0, sgg = 0, sgv = 0;
  for (std::size_t i = 0; i < g.size(); ++i) sg += g[i], sv += v[i], sgg += g[i] * g[i], sgv += g[i] * v[i];
  const double b = (cnt * sgv - sg * sv) / (cnt * sgg - sg * sg), a = (sv - b * sg) / cnt;
  if (a < 0) return std::sqrt(std::max(0.0, sgv / sgg));  // sw^2 >= 0: the fit through the origin
  return std::sqrt(std::max(0.0, a + b));
}

std::optional<double> position_bridge_type_a(std::span<const double> batch_speeds_rpm) {
  const std::size_t n = batch_speeds_rpm.size();
  if (n < 3) return std::nullopt;
  const double B = static_cast<double>(n);
  double mean = 0;
  for (double x : batch_speeds_rpm) mean += x;
  mean /= B;
  double s = 0, ss = 0;  // running sum in units of rpm x tau, over k = 1 .. B-1
  for (std::size_t k = 0; k + 1 < n; ++k) {
    s += batch_speeds_rpm[k] - mean;
    ss += s * s;
  }
  const double var_e = ss / (B - 1) / (1 + (2 * B - 1) / (3 * B));
  return std::sqrt(2 * var_e) / B;
}

std::optional<double> type_a_of_mean(std::span<const double> batch_means) {
  const auto r = batch_type_a(batch_means);
  if (!r) return std::nullopt;
  return r->u;
}

std::vector<double> batch_currents_A(std::span<const std::uint64_t> batch_counts, double gate_s, double f0_Hz,
                                     double kf_Hz_per_A) {
  std::vector<double> out;
  if (batch_counts.empty() || gate_s <= 0 || kf_Hz_per_A <= 0) return out;
  const double sub_s = gate_s / static_cast<double>(batch_counts.size());
  out.reserve(batch_counts.size());
  for (auto n : batch_counts) out.push_back((static_cast<double>(n) / sub_s - f0_Hz) / kf_Hz_per_A);
  return out;
}

PointBudget point_budget(const BudgetInputs& in, const drivers::UncertaintyConfig& cfg) {
  PointBudget b;
  auto& comps = b.components;
  const double w = in.speed_rpm * kRadPerRpm;

  // P_dcM, P_dcG: U_dc x I_dc (physics.md Sec. 3), or a power meter's own.
  if (in.power_meter) {
    for (auto [name, out, p] : {std::tuple{"power meter P_dcM", Output::pdcm_W, in.pdcm_W},
                                std::tuple{"power meter P_dcG", Output::pdcg_W, in.pdcg_W}}) {
      auto c = type_b(name, "[assumed] power meter accuracy, % of reading", "W", std::abs(p) * cfg.power_meter_u_pct / 100.0);
      c.sensitivity[idx(out)] = 1.0;
      comps.push_back(std::move(c));
    }
    for (auto [name, out] : {std::tuple{"P_dcM type A", Output::pdcm_W}, std::tuple{"P_dcG type A", Output::pdcg_W}}) {
      auto c = type_a(name, "batch means, lag-1 (MA(1)) model, GUM 4.2.3", "W", {}, "the power meter");
      c.sensitivity[idx(out)] = 1.0;
      comps.push_back(std::move(c));
    }
  } else {
    static const drivers::MeterReading none;
    const drivers::MeterReading& m = in.meter ? *in.meter : none;
    vfc_channel(comps, "M", m, in.idcm_A, cfg, Output::pdcm_W, in.udc_V);
    vfc_channel(comps, "G", m, in.idcg_A, cfg, Output::pdcg_W, in.udc_V);
    // One U_dc measurement multiplies both currents: its components enter P_dcM and P_dcG.
    for (auto c : {type_b("U_dc gain", "[assumed] drive's U_dc channel, %", "V", std::abs(in.udc_V) * cfg.udc_gain_u_pct / 100.0),
                   type_b("U_dc offset", "[assumed] drive's U_dc channel", "V", cfg.udc_offset_u_V)}) {
      c.sensitivity[idx(Output::pdcm_W)] = in.idcm_A;
      c.sensitivity[idx(Output::pdcg_W)] = in.idcg_A;
      comps.push_back(std::move(c));
    }
  }

  // P_m = T_L w + B1G w^2 (physics.md Sec. 2, eq. 6.1).
  const double c_T = w, c_n = (in.torque_Nm + 2.0 * in.load_b1_Nms_per_rad * w) * kRadPerRpm, c_b1 = w * w;
  {
    static const drivers::LoadWindow no_load;
    auto c = type_a("T_L type A", "load window's batch means, lag-1 (MA(1)) model, GUM 4.2.3", "N m",
                    (in.load ? *in.load : no_load).batch_torque_Nm, "the load drive");
    c.sensitivity[idx(Output::pm_W)] = c_T;
    comps.push_back(std::move(c));
  }
  for (auto c : {type_b("torque gain", "[assumed] load's kt and current sensors, %", "N m",
                        std::abs(in.torque_Nm) * cfg.torque_gain_u_pct / 100.0),
                 type_b("torque offset", "[assumed] load's current sensor offset", "N m", cfg.torque_offset_u_Nm)}) {
    c.sensitivity[idx(Output::pm_W)] = c_T;
    comps.push_back(std::move(c));
  }
  static const drivers::SynrmWindow no_synrm;
  const drivers::SynrmWindow& sw = in.synrm ? *in.synrm : no_synrm;
  if (sw.keeper == drivers::WindowKeeper::device) {
    // The drive's window speed is an encoder count difference over the window: its error is the
    // speed loop's position error at the two ends, not the batches' scatter (which the
    // loop's integral action cancels over the window).
    auto c = type_a("speed type A", "SynRM window's batch speeds, position bridge, GUM 4.2.3", "rpm",
                    sw.batch_speed_meas_rpm, "the SynRM drive", position_bridge_type_a, 3);
    c.sensitivity[idx(Output::pm_W)] = c_n;
    comps.push_back(std::move(c));
  } else {
    // A host-kept window's speed is a mean of polled speeds: no count difference to telescope.
    auto c = type_a("speed type A", "SynRM window's batch means, lag-1 (MA(1)) model, GUM 4.2.3", "rpm", sw.batch_speed_meas_rpm,
                    "the SynRM drive");
    c.sensitivity[idx(Output::pm_W)] = c_n;
    comps.push_back(std::move(c));
  }
  if (in.window_s > 0 && cfg.encoder_counts_per_rev > 0) {
    // Speed from encoder counts over the window: one count, triangular as the VFC's.
    auto c = type_b("encoder quantisation", "physics.md Sec. 2 (12-bit encoder; triangular)", "rpm",
                    60.0 / (std::sqrt(6.0) * cfg.encoder_counts_per_rev * in.window_s), /*repeat=*/true);
    c.sensitivity[idx(Output::pm_W)] = c_n;
    comps.push_back(std::move(c));
  }
  {
    auto c = type_b("B1G", "[assumed] load friction, physics.md Sec. 2 gives 2e-4 [assumed]", "N m s/rad",
                    cfg.load_b1_u_Nms_per_rad);
    c.sensitivity[idx(Output::pm_W)] = c_b1;
    comps.push_back(std::move(c));
  }
  // I_m.
  {
    auto c = type_a("I_m type A", "SynRM window's batch means, lag-1 (MA(1)) model, GUM 4.2.3", "A", sw.batch_im_A, "the SynRM drive");
    c.sensitivity[idx(Output::im_A)] = 1.0;
    comps.push_back(std::move(c));
    auto g = type_b("I_m current sensor gain", "[assumed] SynRM drive's phase current sensors, %", "A",
                    std::abs(in.im_A) * cfg.im_gain_u_pct / 100.0);
    g.sensitivity[idx(Output::im_A)] = 1.0;
    comps.push_back(std::move(g));
  }

  // efficiency = P_m / P_dcM: every input enters through both.
  if (in.pdcm_W > 0)
    for (auto& c : comps)
      c.sensitivity[idx(Output::efficiency)] =
          c.sensitivity[idx(Output::pm_W)] / in.pdcm_W - in.pm_W * c.sensitivity[idx(Output::pdcm_W)] / (in.pdcm_W * in.pdcm_W);

  // Law of propagation, uncorrelated inputs (GUM 5.1.2). Every component is a separate physical
  // source; U_dc enters P_dcM and P_dcG through one component each, so their correlation does
  // not cross outputs here.
  for (std::size_t o = 0; o < kOutputs; ++o) {
    if (o == idx(Output::efficiency) && in.pdcm_W <= 0) continue;
    double all = 0, rep = 0;
    bool all_ok = true, rep_ok = true;
    for (const auto& c : comps) {
      if (c.sensitivity[o] == 0) continue;
      if (!c.u) {
        all_ok = false;
        if (c.repeat) rep_ok = false;
        continue;
      }
      const double ci = c.sensitivity[o] * *c.u;
      all += ci * ci;
      if (c.repeat) rep += ci * ci;
    }
    if (all_ok) b.combined[o] = std::sqrt(all);
    if (rep_ok) b.repeat[o] = std::sqrt(rep);
  }
  for (const auto& c : comps)
    if (!c.u) b.notes.push_back(c.name + " unavailable: " + c.why + "; the uncertainties it enters are null");
  b.notes.push_back("inputs taken as uncorrelated (GUM 5.1.2); k = 1");
  return b;
}

synbench::Json to_json(const PointBudget& b) {
  synbench::Json j = synbench::Json::object();
  synbench::Json comps = synbench::Json::array();
  for (const auto& c : b.components) {
    synbench::Json e = synbench::Json::object();
    e["name"] = c.name;
    e["type"] = std::string(1, c.type);
    e["source"] = c.source;
    e["unit"] = c.unit;
    e["u"] = c.u ? synbench::Json(*c.u) : synbench::Json(nullptr);
    if (!c.u) e["unavailable"] = c.why;
    e["repeat"] = c.repeat;
    synbench::Json sens = synbench::Json::object(), contrib = synbench::Json::object();
    for (std::size_t o = 0; o < kOutputs; ++o) {
      if (c.sensitivity[o] == 0) continue;
      sens[kOutputNames[o]] = c.sensitivity[o];
      contrib[kOutputNames[o]] = c.u ? synbench::Json(std::abs(c.sensitivity[o] * *c.u)) : synbench::Json(nullptr);
    }
    e["sensitivity"] = std::move(sens);
    e["contribution"] = std::move(contrib);
    comps.push_back(std::move(e));
  }
  j["components"] = std::move(comps);
  synbench::Json comb = synbench::Json::object(), rep = synbench::Json::object();
  for (std::size_t o = 0; o < kOutputs; ++o) {
    comb[kOutputNames[o]] = b.combined[o] ? synbench::Json(*b.combined[o]) : synbench::Json(nullptr);
    rep[kOutputNames[o]] = b.repeat[o] ? synbench::Json(*b.repeat[o]) : synbench::Json(nullptr);
  }
  j["combined"] = std::move(comb);
  j["repeat"] = std::move(rep);
  j["notes"] = b.notes;
  return j;
}

std::string to_text(const PointBudget& b) {
  std::ostringstream s;
  char buf[512];
  auto num = [](std::optional<double> v) {
    char t[32];
    if (v) std::snprintf(t, sizeof t, "%.3g", *v);
    else std::snprintf(t, sizeof t, "-");
    return std::string(t);
  };
  std::snprintf(buf, sizeof buf, "%-32s %-2s %-62s %-3s %-10s %-10s %-20s %-10s %-10s %-10s %-10s %-10s\n", "component",
                "ty", "source", "rep", "u_i", "unit", "sensitivity", "pdcm_W", "pdcg_W", "pm_W", "efficiency", "im_A");
  s << buf;
  for (const auto& c : b.components) {
    // The sensitivity to the first output the component enters (the JSON has all of them).
    std::string sens = "-";
    for (std::size_t o = 0; o < kOutputs; ++o)
      if (c.sensitivity[o] != 0) {
        sens = num(c.sensitivity[o]) + " (" + kOutputNames[o] + ")";
        break;
      }
    std::string cols;
    for (std::size_t o = 0; o < kOutputs; ++o) {
      char t[16];
      std::snprintf(t, sizeof t, " %-10s",
                    c.sensitivity[o] == 0 ? "" : c.u ? num(std::abs(c.sensitivity[o] * *c.u)).c_str() : "null");
      cols += t;
    }
    std::snprintf(buf, sizeof buf, "%-32s %-2c %-62s %-3s %-10s %-10s %-20s", c.name.c_str(), c.type, c.source.c_str(),
                  c.repeat ? "yes" : "no", num(c.u).c_str(), c.unit.c_str(), sens.c_str());
    s << buf << cols << "\n";
  }
  std::string comb, rep;
  for (std::size_t o = 0; o < kOutputs; ++o) {
    char t[16];
    std::snprintf(t, sizeof t, " %-10s", num(b.combined[o]).c_str());
    comb += t;
    std::snprintf(t, sizeof t, " %-10s", num(b.repeat[o]).c_str());
    rep += t;
  }
  std::snprintf(buf, sizeof buf, "%-32s %-2s %-62s %-3s %-10s %-10s %-20s", "combined u (k = 1)", "", "", "", "", "", "");
  s << buf << comb << "\n";
  std::snprintf(buf, sizeof buf, "%-32s %-2s %-62s %-3s %-10s %-10s %-20s", "  of which repeat", "", "", "", "", "", "");
  s << buf << rep << "\n";
  for (const auto& n : b.notes) s << "note: " << n << "\n";
  return s.str();
}

}  // namespace synbench::bench
