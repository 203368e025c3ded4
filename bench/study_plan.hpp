// A twin study plan (docs/study.md): one sweep plan crossed with deviations of the plant's
// parameters, as a grid or a seeded Monte Carlo. Parsed from JSON with every problem at its JSON
// pointer, written back in canonical form, and expanded sample by sample: sample i's deviation,
// noise seed and store key follow from the canonical plan and i alone, so any process (a shard
// of a cluster job) computes the same samples without talking to the others. Pure logic.
#pragma once

#include "drivers/json_fwd.hpp"
#include "drivers/json_reader.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bench/sweep_plan.hpp"

namespace synbench::bench {

// The plant parameters a study varies (emulator::apply_plant_deviation applies them), in their
// canonical order, with the range a deviation must stay within.
enum class StudyParameter { ld_pct, lq_pct, rs_pct, inertia_pct, encoder_offset_deg, meter_kf_pct, meter_f0_ppm };
inline constexpr std::array<std::string_view, 7> kStudyParameterNames{
    "ld_pct", "lq_pct", "rs_pct", "inertia_pct", "encoder_offset_deg", "meter_kf_pct", "meter_f0_ppm"};
struct StudyParameterRange {
  double min, max;
};
inline constexpr std::array<StudyParameterRange, 7> kStudyParameterRanges{{
    {-75, 300}, {-75, 300}, {-75, 300}, {-75, 300}, {-180, 180}, {-40, 40}, {-100000, 100000}}};
inline std::string_view name(StudyParameter p) { return kStudyParameterNames[static_cast<std::size_t>(p)]; }

enum class StudyDistribution { uniform, normal };
inline constexpr std::array<std::string_view, 2> kStudyDistributionNames{"uniform", "normal"};
// A normal draw is cut at this many standard deviations (drawn again), so a deviation is bounded.
inline constexpr double kNormalTruncation_sd = 4.0;

// One parameter of a Monte Carlo study: uniform in mean +/- half_width, or normal(mean, sd).
struct StudyDraw {
  StudyParameter parameter = StudyParameter::ld_pct;
  StudyDistribution distribution = StudyDistribution::uniform;
  double mean = 0;
  double width = 0;  // the half-width (uniform) or standard deviation (normal), in the parameter's unit
  bool operator==(const StudyDraw&) const = default;
};

enum class StudyKind { grid, monte_carlo };
inline constexpr std::array<std::string_view, 2> kStudyKindNames{"grid", "monte-carlo"};

struct StudyPlan {
  std::string name;   // [A-Za-z0-9._-]+: part of every sample's key
  SweepPlan sweep;    // every sample runs it
  StudyKind kind = StudyKind::grid;
  // grid: every combination, the first parameter outermost (canonical parameter order).
  std::vector<std::pair<StudyParameter, std::vector<double>>> grid;
  // monte_carlo
  std::size_t samples = 0;
  std::uint64_t seed = 0;
  std::vector<StudyDraw> draws;  // canonical parameter order
  // The twin's noise seed: the sweep's twin config's for every sample (false), or
  // base + sample index, so every sample also sees other noise (true).
  bool noise_seed_per_sample = false;
  bool operator==(const StudyPlan&) const = default;
};

struct StudyPlanParseResult {
  std::optional<StudyPlan> plan;            // set exactly when errors is empty
  std::vector<drivers::JsonError> errors;   // every problem; the sweep's under /sweep
};

StudyPlanParseResult parse_study_plan(const synbench::Json& doc);

// Canonical form: the sweep in its canonical form, every field explicit, parameters in canonical
// order. parse_study_plan(to_json(p)) gives p back.
synbench::Json to_json(const StudyPlan& plan);

// 16 hex digits of FNV-1a 64 over the canonical form's compact dump: any change to the plan
// (sweep, deviations, seed) gives other keys, so a changed plan never resumes an old one's sweeps.
std::string plan_hash(const StudyPlan& plan);

std::size_t sample_count(const StudyPlan& plan);

struct StudySample {
  std::size_t index = 0;
  // Every parameter the plan varies, in canonical order (0 where a grid value is 0).
  std::vector<std::pair<StudyParameter, double>> deviation;
  std::optional<int> noise_seed_offset;  // noise_seed_per_sample: add to the twin's seed
  std::string key;                       // sample_key(plan, index)
};

// Sample `index` (< sample_count). Monte Carlo draws come from SplitMix64 of (seed, index,
// parameter), independent of every other sample, rounded to 1e-9 of the unit.
StudySample sample(const StudyPlan& plan, std::size_t index);

// "<name>/<plan_hash>/<index>": the store key of the sample's sweep.
std::string sample_key(const StudyPlan& plan, std::size_t index);
// "<name>/<plan_hash>/": every key of the plan starts with it.
std::string key_prefix(const StudyPlan& plan);
// The sample index of a key with this plan's prefix, else nullopt.
std::optional<std::size_t> sample_index(const StudyPlan& plan, std::string_view key);

// Shard K of N (0 <= K < N) takes the samples i with i % N == K: interleaved, so every shard
// gets a share of each region of a grid and shards finish at about the same time.
struct Shard {
  std::size_t index = 0;
  std::size_t count = 1;
  bool operator==(const Shard&) const = default;
};
// "K/N"; the reason when it is not.
std::optional<Shard> parse_shard(std::string_view text, std::string* reason = nullptr);
inline bool in_shard(std::size_t sample_index, Shard s) { return sample_index % s.count == s.index; }
std::vector<std::size_t> shard_samples(const StudyPlan& plan, Shard shard);

}  // namespace synbench::bench
