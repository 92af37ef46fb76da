#pragma once
// The study figures (docs/fits.md §6): the log-log regime diagram (L_p/H_i or D_p/H_i against Π, with
// quartile bars, failed cases, the fitted law(s), 95 % bands and the breakpoint interval) and
// empirical CDFs of several samples. Both return a Figure to write as PNG and/or SVG.
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "analysis/broken_line_fit.hpp"
#include "analysis/plot.hpp"
#include "analysis/power_law_fit.hpp"

namespace crevasse::analysis {

struct RegimePoint {
  double pi = 0.0;  // x: Π (or whichever group the diagram is drawn against)
  double y = 0.0;   // median, e.g. L_p/H_i
  double y_q25 = std::numeric_limits<double>::quiet_NaN();  // quartiles: the error bar
  double y_q75 = std::numeric_limits<double>::quiet_NaN();
  std::string group;    // colour/marker group (e.g. "H_i = 200 m")
  bool failed = false;  // no value: drawn as a cross on the bottom edge, never dropped
  // Why a failed point has no value. Each distinct reason gets its own bottom-edge marker
  // (cross, plus, then hollow shapes) and legend entry, e.g. "failed" and "no crevasse".
  std::string missing_reason = "failed / no crevasse";
  // A value drawn hollow and left out of the legend's group entry, e.g. an under-resolved case
  // that was not fitted; the legend names it once.
  bool hollow = false;
  std::string hollow_reason = "under-resolved, not fitted";
};

// No fit, one power law, or a broken line.
using RegimeFit = std::variant<std::monostate, PowerLawFit, BrokenLineFit>;

// A curve drawn dashed under the data, with its legend (e.g. Nye's zero-stress depth).
struct ReferenceCurve {
  std::string legend;
  std::vector<double> x, y;
};

// Nye's zero-stress depth D = 2c/(ρ_i g) as D/H_i = 2Π, capped at the bed (D/H_i = 1), sampled
// log-evenly over [pi_lo, pi_hi] (docs/fits.md, "Nye's zero-stress depth"). Throws
// std::invalid_argument unless 0 < pi_lo <= pi_hi and points >= 1.
ReferenceCurve nye_zero_stress_depth(double pi_lo, double pi_hi, int points = 64);

struct RegimeDiagramOptions {
  std::string title;
  std::vector<ReferenceCurve> references;
  // Each shaded lightly from the smallest x drawn up to it, so that overlaps darken (e.g. each
  // H_i's resolution floor Π = 3 dx/H_i); one legend entry.
  std::vector<double> shade_below;
  std::string shade_legend = "under-resolved below (c/(ρ_i g) < 3 dx), per H_i";
  std::string x_label = "Π = c/(ρ_i g H_i)";
  std::string y_label = "L_p/H_i";
  std::string x_symbol = "Π";  // used in the exponent and breakpoint text
  double width_pt = 480.0;
  double height_pt = 360.0;
  LegendPosition legend = LegendPosition::upper_left;
};

// Throws std::invalid_argument when a non-failed point has a non-finite or non-positive Π or y
// (naming it), or when there is nothing to draw.
Figure regime_diagram(const std::vector<RegimePoint>& points, const RegimeFit& fit = {},
                      const RegimeDiagramOptions& options = {});

struct NamedSample {
  std::string name;
  std::vector<double> values;
};

struct CdfFigureOptions {
  std::string title;
  std::string x_label = "L_p [m]";
  std::string y_label = "empirical CDF F(x)";
  AxisScale x_scale = AxisScale::linear;
  double width_pt = 480.0;
  double height_pt = 360.0;
  LegendPosition legend = LegendPosition::lower_right;
};

// Step-function CDFs, one per sample, labelled "name (n = …)". Throws std::invalid_argument
// for an empty list, an empty sample, or a non-finite value (naming sample and index).
Figure empirical_cdf_figure(const std::vector<NamedSample>& samples,
                            const CdfFigureOptions& options = {});

}  // namespace crevasse::analysis
