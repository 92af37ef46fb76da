#pragma once
// `crevasse fit DB`: fits median L_p/H_i and D_p/H_i against Π (or other groups) with a single
// power law and a broken line (docs/fits.md), prints the table and stores it in the database's
// `fits` table (docs/database.md).
#include <string>
#include <vector>

#include "study/case_results.hpp"

namespace crevasse {

struct FitCommandOptions {
  std::string db_path;
  std::vector<std::string> groups;    // group names, or "all" (every group that varies); default Π
  std::string fixed_exponents;        // broken line of L_p/H_i: "B1,B2", each a number or "free"
  std::string fixed_depth_exponents;  // the same for D_p/H_i
  double level = 0.95;
  bool exclude_fragmented = false;
  bool include_under_resolved = false;  // fit cases with c/(ρ_i g) < 3 dx too
  bool no_store = false;  // print only
  // The whole window, the ramp's ice or the window clear of the front (docs/measurement.md).
  CaseReading reading = CaseReading::window;
};

int fit_command(const FitCommandOptions& opt);

}  // namespace crevasse
