// The merged result of a twin study (docs/study.md): every sample's points, whichever shard
// stored them, grouped per varied parameter by its value (grid) or bin (Monte Carlo) and per
// configuration: the estimators' position and speed errors, the efficiency, and the MTPA angle's
// shift against the nominal plant (the value or bin holding a zero deviation). The thesis' Ch. 4
// question in numbers: how an estimator's error grows as the machine leaves its model. Pure.
#pragma once

#include "drivers/json_fwd.hpp"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "bench/point_record.hpp"
#include "bench/study_plan.hpp"
#include "bench/sweep_plan_configuration.hpp"

namespace synbench::bench {

struct StudySampleRecords {
  StudySample sample;
  std::vector<PointRecord> records;  // the sample's stored points (complete or not)
};

// One configuration at one value (or bin) of one parameter, over every sample in it.
struct StudyCell {
  Configuration configuration;
  std::size_t samples = 0, points = 0;
  std::optional<double> pos_err_abs_mean_deg;  // mean over points of |window-mean position error|
  std::optional<double> pos_err_abs_max_deg;   // largest |error| any window saw
  std::optional<double> speed_err_abs_mean_rpm;
  std::optional<double> efficiency_mean;
  std::optional<double> mtpa_angle_mean_deg;   // mean over the curves of the samples' MTPA angles
  std::optional<double> mtpa_shift_deg;        // against the nominal value or bin, curve by curve
};

struct StudyGroup {
  double from = 0, to = 0;  // the grid value (from == to) or the bin [from, to)
  bool nominal = false;     // holds a zero deviation: the shifts' reference
  std::vector<StudyCell> cells;  // by configuration
};

struct StudyParameterResult {
  StudyParameter parameter = StudyParameter::ld_pct;
  std::vector<StudyGroup> groups;  // ascending
};

struct StudyAnalysis {
  std::size_t samples_planned = 0, samples_with_points = 0, points = 0;
  std::vector<StudyParameterResult> parameters;
};

// `bins`: Monte Carlo samples are binned over the drawn range in this many equal bins.
StudyAnalysis analyze_study(const StudyPlan& plan, const std::vector<StudySampleRecords>& samples,
                            std::size_t bins = 8);

synbench::Json to_json(const StudyAnalysis& a);
// One line per (parameter, value or bin, configuration), aligned for a terminal.
std::string study_table(const StudyAnalysis& a);

}  // namespace synbench::bench
