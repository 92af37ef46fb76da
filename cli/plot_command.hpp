#pragma once
// `crevasse plot DB --out DIR`: the study's figures (docs/fits.md §6) as PNG and SVG:
// regime diagrams of median L_p/H_i and D_p/H_i against Π (or another group) with the fitted
// law(s), and empirical CDFs of the spacings of chosen cases.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "study/case_results.hpp"

namespace crevasse {

struct PlotCommandOptions {
  std::string db_path;
  std::string out_dir;
  std::string group = "cohesion_ratio";  // horizontal axis
  std::string colour_by = "thickness";   // marker colour/shape
  std::string model = "auto";            // auto, single, broken, none
  std::string fixed_exponents;           // as crevasse fit; default: what the fits table used
  std::string fixed_depth_exponents;
  std::vector<std::int64_t> cdf_cases;   // case_index values; default: up to 4 spread over Π
  std::string cdf_normalise = "median";  // median, thickness, none
  double level = 0.95;
  bool exclude_fragmented = false;
  bool include_under_resolved = false;  // fit cases with c/(ρ_i g) < 3 dx too
  CaseReading reading = CaseReading::window;  // as crevasse fit, with that reading's stored fits
  // Other study databases whose cases are drawn on the regime diagrams too (not fitted),
  // labelled "<their study name>: ...", e.g. 3D cases on their 2D study's diagram.
  std::vector<std::string> add_cases;
};

// Returns the files written.
std::vector<std::filesystem::path> plot_study(const PlotCommandOptions& opt);

int plot_command(const PlotCommandOptions& opt);

}  // namespace crevasse
