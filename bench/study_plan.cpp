// Parsing, canonical form, samples and keys of twin study plans; see study_plan.hpp.
#include "bench/study_plan.hpp"

#include "drivers/json.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace synbench::bench {
namespace {

using json = synbench::Json;
using drivers::JsonNode;
using drivers::JsonReader;

constexpr std::size_t kMaxSamples = 1000000;
constexpr std::size_t kMaxGridValues = 1000;
constexpr double kPi = 3.14159265358979323846;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

bool valid_name(const std::string& s) {
  return !s.empty() && s.size() <= 64 && std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
           c == '-';
  });
}

std::optional<StudyParameter> parameter_named(std::string_view s) {
  for (std::size_t i = 0; i < kStudyParameterNames.size(); ++i)
    if (kStudyParameterNames[i] == s) return static_cast<StudyParameter>(i);
  return std::nullopt;
}

StudyParameterRange range_of(StudyParameter p) { return kStudyParameterRanges[static_cast<std::size_t>(p)]; }

std::string range_text(StudyParameter p) {
  const auto r = range_of(p);
  return "[" + num(r.min) + ", " + num(r.max) + "]";
}

double round9(double v) { return std::round(v * 1e9) / 1e9; }

// SplitMix64: a tiny, fully specified generator, so a draw is the same on every platform.
std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}
// Uniform in (0, 1) from 53 bits.
double unit(std::uint64_t x) { return (static_cast<double>(x >> 11) + 0.5) * 0x1.0p-53; }

// The sweep: a preset's name or a sweep plan document; its problems under /sweep.
std::optional<SweepPlan> read_sweep(const JsonNode& n) {
  if (!n.present()) {
    n.fail("required field is missing");
    return std::nullopt;
  }
  json doc = n.json();
  if (doc.is_string()) doc = json{{"preset", doc}};
  if (!doc.is_object()) {
    n.fail("must be a preset name or a sweep plan object (docs/sweep-plan.md)");
    return std::nullopt;
  }
  auto parsed = parse_sweep_plan(doc);
  for (auto& e : parsed.errors) n.reader().fail(n.pointer() + e.pointer, e.reason);
  return std::move(parsed.plan);
}

void read_grid(const JsonNode& n, StudyPlan& plan) {
  if (!n.object()) return;
  for (auto& [key, values] : n.members()) {
    const auto p = parameter_named(key);
    if (!p) {
      values.fail(JsonNode::unknown_choice("study parameter", key, JsonNode::names_list(kStudyParameterNames)));
      continue;
    }
    const auto list = values.list("must be a list of deviations", true);
    if (!list) continue;
    if (list->size() > kMaxGridValues) {
      values.fail("more than " + std::to_string(kMaxGridValues) + " values");
      continue;
    }
    std::vector<double> v;
    for (const auto& e : *list) {
      const auto r = range_of(*p);
      const auto x = e.number([&](double d) {
        return d >= r.min && d <= r.max ? std::string() : "must be within " + range_text(*p);
      });
      if (!x) continue;
      if (std::find(v.begin(), v.end(), *x) != v.end()) e.fail("repeats " + num(*x));
      v.push_back(*x);
    }
    plan.grid.emplace_back(*p, std::move(v));
  }
  if (n.members().empty()) n.fail("must vary at least one parameter");
  std::sort(plan.grid.begin(), plan.grid.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
}

void read_monte_carlo(const JsonNode& n, StudyPlan& plan) {
  if (!n.object()) return;
  n.reject_unknown({"samples", "seed", "parameters"});
  if (auto s = n["samples"].required().integer(1, static_cast<std::int64_t>(kMaxSamples)))
    plan.samples = static_cast<std::size_t>(*s);
  if (auto s = n["seed"].required().integer(0, INT64_MAX)) plan.seed = static_cast<std::uint64_t>(*s);
  const JsonNode params = n["parameters"];
  if (!params.required().object()) return;
  for (auto& [key, d] : params.members()) {
    const auto p = parameter_named(key);
    if (!p) {
      d.fail(JsonNode::unknown_choice("study parameter", key, JsonNode::names_list(kStudyParameterNames)));
      continue;
    }
    if (!d.object()) continue;
    StudyDraw draw;
    draw.parameter = *p;
    const auto dist = d["distribution"].required().choice<StudyDistribution>(kStudyDistributionNames, "distribution");
    if (!dist) continue;
    draw.distribution = *dist;
    const char* width_key = *dist == StudyDistribution::uniform ? "half_width" : "sd";
    d.reject_unknown({"distribution", "mean", width_key});
    if (auto m = d["mean"].number()) draw.mean = *m;
    const auto w = d[width_key].required().number(drivers::non_negative());
    if (!w) continue;
    draw.width = *w;
    // The widest deviation the draw can give must stay within the parameter's range.
    const double reach = *dist == StudyDistribution::uniform ? draw.width : kNormalTruncation_sd * draw.width;
    const auto r = range_of(*p);
    if (draw.mean - reach < r.min || draw.mean + reach > r.max)
      d.fail("mean +/- " + std::string(*dist == StudyDistribution::uniform ? "half_width" : "4 sd") + " (" +
             num(draw.mean - reach) + " .. " + num(draw.mean + reach) + ") must stay within " + range_text(*p));
    plan.draws.push_back(draw);
  }
  if (params.members().empty()) params.fail("must vary at least one parameter");
  std::sort(plan.draws.begin(), plan.draws.end(),
            [](const StudyDraw& a, const StudyDraw& b) { return a.parameter < b.parameter; });
}

std::uint64_t fnv1a64(std::string_view s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

}  // namespace

StudyPlanParseResult parse_study_plan(const json& doc) {
  JsonReader reader;
  const JsonNode root(&doc, "", reader);
  StudyPlan plan;
  if (!root.object("a study plan must be a JSON object")) return {std::nullopt, reader.errors};
  root.reject_unknown({"name", "sweep", "grid", "monte_carlo", "noise_seed_per_sample"});
  if (auto n = root["name"].required().text(true)) {
    if (valid_name(*n)) plan.name = *n;
    else root["name"].fail("must be 1..64 characters of A-Z a-z 0-9 . _ - (it is part of every sample's key)");
  }
  if (auto s = read_sweep(root["sweep"])) plan.sweep = std::move(*s);
  const bool grid = root.has("grid"), mc = root.has("monte_carlo");
  if (grid == mc) {
    root.fail(grid ? "give either grid or monte_carlo, not both" : "requires grid or monte_carlo (the deviations)");
  } else if (grid) {
    plan.kind = StudyKind::grid;
    read_grid(root["grid"], plan);
    std::size_t n = 1;
    for (const auto& [p, v] : plan.grid) n = std::min(kMaxSamples + 1, n * std::max<std::size_t>(1, v.size()));
    if (n > kMaxSamples) root["grid"].fail("more than " + std::to_string(kMaxSamples) + " combinations");
  } else {
    plan.kind = StudyKind::monte_carlo;
    read_monte_carlo(root["monte_carlo"], plan);
  }
  if (auto b = root["noise_seed_per_sample"].boolean()) plan.noise_seed_per_sample = *b;
  if (!reader.ok()) return {std::nullopt, reader.errors};
  return {std::move(plan), {}};
}

json to_json(const StudyPlan& plan) {
  json j;
  j["name"] = plan.name;
  j["sweep"] = to_json(plan.sweep);
  if (plan.kind == StudyKind::grid) {
    json g = json::object();
    for (const auto& [p, v] : plan.grid) g[std::string(name(p))] = v;
    j["grid"] = g;
  } else {
    json params = json::object();
    for (const auto& d : plan.draws) {
      json e;
      e["distribution"] = kStudyDistributionNames[static_cast<std::size_t>(d.distribution)];
      e["mean"] = d.mean;
      e[d.distribution == StudyDistribution::uniform ? "half_width" : "sd"] = d.width;
      params[std::string(name(d.parameter))] = e;
    }
    j["monte_carlo"] = {{"samples", plan.samples}, {"seed", plan.seed}, {"parameters", params}};
  }
  j["noise_seed_per_sample"] = plan.noise_seed_per_sample;
  return j;
}

std::string plan_hash(const StudyPlan& plan) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(fnv1a64(to_json(plan).dump())));
  return buf;
}

std::size_t sample_count(const StudyPlan& plan) {
  if (plan.kind == StudyKind::monte_carlo) return plan.samples;
  std::size_t n = 1;
  for (const auto& [p, v] : plan.grid) n *= v.size();
  return plan.grid.empty() ? 0 : n;
}

std::string key_prefix(const StudyPlan& plan) { return plan.name + "/" + plan_hash(plan) + "/"; }

std::string sample_key(const StudyPlan& plan, std::size_t index) { return key_prefix(plan) + std::to_string(index); }

std::optional<std::size_t> sample_index(const StudyPlan& plan, std::string_view key) {
  const std::string prefix = key_prefix(plan);
  if (key.substr(0, prefix.size()) != prefix) return std::nullopt;
  const std::string_view rest = key.substr(prefix.size());
  std::size_t i = 0;
  const auto [end, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), i);
  if (ec != std::errc() || end != rest.data() + rest.size() || rest.empty()) return std::nullopt;
  return i;
}

StudySample sample(const StudyPlan& plan, std::size_t index) {
  StudySample s;
  s.index = index;
  s.key = sample_key(plan, index);
  if (plan.noise_seed_per_sample) s.noise_seed_offset = static_cast<int>(index % 1000000007);
  if (plan.kind == StudyKind::grid) {
    // Mixed radix, the last parameter fastest.
    std::size_t rest = index;
    s.deviation.resize(plan.grid.size());
    for (std::size_t k = plan.grid.size(); k-- > 0;) {
      const auto& [p, v] = plan.grid[k];
      s.deviation[k] = {p, v[rest % v.size()]};
      rest /= v.size();
    }
    return s;
  }
  for (const auto& d : plan.draws) {
    // One stream per (seed, sample, parameter): adding a parameter leaves the others' draws alone.
    std::uint64_t state = splitmix64(plan.seed ^ splitmix64(index ^ splitmix64(static_cast<std::uint64_t>(d.parameter) + 1)));
    auto next = [&state] {
      state = splitmix64(state);
      return unit(state);
    };
    double x = 0;
    if (d.distribution == StudyDistribution::uniform) {
      x = d.mean + d.width * (2.0 * next() - 1.0);
    } else {
      double z = 0;
      do {  // Box-Muller, cut at kNormalTruncation_sd
        z = std::sqrt(-2.0 * std::log(next())) * std::cos(2.0 * kPi * next());
      } while (std::fabs(z) > kNormalTruncation_sd);
      x = d.mean + d.width * z;
    }
    s.deviation.emplace_back(d.parameter, round9(x));
  }
  return s;
}

std::optional<Shard> parse_shard(std::string_view text, std::string* reason) {
  auto fail = [&](std::string r) -> std::optional<Shard> {
    if (reason) *reason = std::move(r);
    return std::nullopt;
  };
  const auto slash = text.find('/');
  if (slash == std::string_view::npos) return fail("must be K/N (shard K of N, 0 <= K < N)");
  Shard s;
  const auto a = text.substr(0, slash), b = text.substr(slash + 1);
  const auto ra = std::from_chars(a.data(), a.data() + a.size(), s.index);
  const auto rb = std::from_chars(b.data(), b.data() + b.size(), s.count);
  if (a.empty() || b.empty() || ra.ec != std::errc() || rb.ec != std::errc() || ra.ptr != a.data() + a.size() ||
      rb.ptr != b.data() + b.size())
    return fail("must be K/N with whole numbers (shard K of N, 0 <= K < N)");
  if (s.count < 1 || s.count > 100000) return fail("N must be within 1..100000");
  if (s.index >= s.count) return fail("K must be below N (shards are numbered 0 .. N-1)");
  return s;
}

std::vector<std::size_t> shard_samples(const StudyPlan& plan, Shard shard) {
  std::vector<std::size_t> out;
  for (std::size_t i = shard.index; i < sample_count(plan); i += shard.count) out.push_back(i);
  return out;
}

}  // namespace synbench::bench
