#pragma once
// `crevasse calibrate` and `crevasse predict` (docs/fits.md §5): the study's laws of
// L_p/H_i (and D_p/H_i) against Π = c/(ρ_i g H_i), inverted to estimate the tensile strength c
// from an observed crevasse spacing, or used forwards to predict spacing and depth for a given c
// and H_i. The laws are the rows of the database's `fits` table (crevasse fit); when the table
// has none, the same fits are computed in memory with the defaults. No extrapolation: an
// observation outside what the study covered is refused (exit 2).
#include <optional>
#include <string>

#include "study/case_results.hpp"

namespace crevasse {

struct CalibrateCommandOptions {
  std::string db_path;
  double spacing_m = 0.0;
  std::string spacing_quartiles;  // "q25,q75" [m], or empty
  std::optional<double> thickness_m;
  double level = 0.95;
  std::string observations_path;  // --observations FILE: every site of the file, as a table
  std::string csv_path;           // --csv PATH: the table also as CSV (with --observations)
  CaseReading reading = CaseReading::window;  // the laws fitted so (crevasse fit --ramp-ice, ...)
};

struct PredictCommandOptions {
  std::string db_path;
  double tensile_strength_pa = 0.0;
  double thickness_m = 0.0;
  double level = 0.95;
  CaseReading reading = CaseReading::window;
};

int calibrate_command(const CalibrateCommandOptions& opt);
int predict_command(const PredictCommandOptions& opt);

}  // namespace crevasse
