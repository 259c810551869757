// Coverage-over-time plots (paper Section V): one PNG per scene, one line per method/variant,
// the mean over seeds of each run's coverage_over_time. Pixels and PNG writing come from
// tools/sim/render.hpp (Image); text is a 5x7 bitmap font drawn here.
#pragma once

#include <string>
#include <vector>

#include "tools/eval/run_record.hpp"

namespace storey::tools::eval {

struct CoverageCurve {
  std::string label;         // "storey", "tare-like", "storey-no-c-sur"
  size_t runs = 0;           // seeds averaged
  std::vector<double> t;     // [s], uniform grid from 0
  std::vector<double> mean;  // 0..1
};

// Mean over `runs` (finished ones only) on a grid of step `dt` up to `t_end` (inclusive). Each
// run's coverage is held between samples (step function), 0 before its first sample and at its
// last value after the run ended (a finished exploration keeps what it mapped).
CoverageCurve mean_coverage_curve(const std::vector<const RunOutcome*>& runs, double dt,
                                  double t_end);

// Writes a PNG of the curves (x: time [s], y: coverage [%]); throws std::runtime_error naming
// the file on failure.
void write_coverage_plot(const std::string& path, const std::string& title,
                         const std::vector<CoverageCurve>& curves);

}  // namespace storey::tools::eval
