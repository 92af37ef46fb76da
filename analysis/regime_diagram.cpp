#include "analysis/regime_diagram.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

namespace crevasse::analysis {
namespace {

const Color kFitLine{0.1, 0.1, 0.1, 1.0};
const Color kFitBand{0.35, 0.35, 0.35, 0.22};
const Color kBreakBand{0.902, 0.624, 0.0, 0.22};  // Okabe–Ito orange, light
const Color kUnderResolvedBand{0.5, 0.5, 0.5, 0.10};  // overlapping floors darken
const Color kReferenceLine{0.0, 0.447, 0.698, 0.9};   // Okabe–Ito blue
const Color kFailed{0.35, 0.35, 0.35, 1.0};

std::string fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}

std::string significant(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.3g", value);
  return buffer;
}

// "b = 0.52 [0.47, 0.57]" or "b = 1 (fixed)".
std::string exponent_text(const std::string& name, double b, const ConfidenceInterval& ci,
                          bool is_fixed) {
  if (is_fixed) return name + " = " + significant(b) + " (fixed)";
  return name + " = " + fixed(b, 2) + " [" + fixed(ci.lower, 2) + ", " + fixed(ci.upper, 2) + "]";
}

std::vector<double> log_spaced(double lo, double hi, int count) {
  std::vector<double> x(count);
  for (int i = 0; i < count; ++i) {
    x[i] = lo * std::pow(hi / lo, static_cast<double>(i) / (count - 1));
  }
  return x;
}

// Curve and band sampled over the fitted data range, with the breakpoint itself included so
// that the kink is drawn sharp.
template <class Value, class Band>
void add_fit_curve(Figure& figure, std::vector<double> x, Value&& value, Band&& band,
                   const std::string& curve_legend) {
  std::sort(x.begin(), x.end());
  std::vector<double> y, lo, hi;
  for (double xi : x) {
    y.push_back(value(xi));
    const ConfidenceInterval b = band(xi);
    lo.push_back(b.lower);
    hi.push_back(b.upper);
  }
  figure.add_band(x, lo, hi, kFitBand, "95 % confidence band");
  figure.add_line(x, y, {kFitLine, 1.6, {}}, curve_legend);
}

// Each add_* draws the fit and returns its annotation lines, top to bottom.
std::vector<std::string> add_power_law(Figure& figure, const PowerLawFit& fit,
                                       const RegimeDiagramOptions& options) {
  const PowerLaw& law = fit.law;
  add_fit_curve(
      figure, log_spaced(fit.x_min, fit.x_max, 120), [&](double x) { return law.value(x); },
      [&](double x) { return law.confidence_band(x, fit.level); }, "power-law fit");
  return {options.y_label + " = " + significant(fit.a()) + " " + options.x_symbol + "^{" +
              fixed(fit.b(), 2) + "}",
          exponent_text("b", fit.b(), fit.ci_b, false) + ",  R^2 = " + fixed(fit.r_squared, 3) +
              ",  n = " + std::to_string(fit.n)};
}

std::vector<std::string> add_broken_line(Figure& figure, const BrokenLineFit& fit,
                                         const RegimeDiagramOptions& options) {
  const double lo = std::min(fit.segment_x_min[0], fit.segment_x_min[1]);
  const double hi = std::max(fit.segment_x_max[0], fit.segment_x_max[1]);
  std::vector<double> x = log_spaced(lo, hi, 160);
  x.push_back(fit.breakpoint);
  figure.add_vertical_band(fit.breakpoint_ci.lower, fit.breakpoint_ci.upper, kBreakBand,
                           options.x_symbol + "^* 95 % interval");
  figure.add_vertical_line(fit.breakpoint, {{0.70, 0.45, 0.0, 1.0}, 1.0, {4.0, 3.0}}, {});
  // The single law, thin and dashed, shows what the second regime buys.
  const std::vector<double> ends = log_spaced(lo, hi, 2);
  figure.add_line(ends, {fit.single.law.value(ends[0]), fit.single.law.value(ends[1])},
                  {{0.45, 0.45, 0.45, 1.0}, 0.9, {2.0, 2.0}}, "single power law");
  add_fit_curve(
      figure, x, [&](double xi) { return fit.value(xi); },
      [&](double xi) { return fit.confidence_band(xi); }, "broken-line fit");

  const std::string clipped_low = fit.breakpoint_ci_clipped_low ? "≤" : "";
  const std::string clipped_high = fit.breakpoint_ci_clipped_high ? "≥" : "";
  const ModelComparison& c = fit.comparison;
  const std::string test = std::isnan(c.p_value) ? "F test n/a"
                           : c.p_value < 0.001   ? "F test p < 0.001"
                                                 : "F test p = " + significant(c.p_value);
  return {options.x_symbol + "^* = " + significant(fit.breakpoint) + " [" + clipped_low +
              significant(fit.breakpoint_ci.lower) + ", " + clipped_high +
              significant(fit.breakpoint_ci.upper) + "]",
          exponent_text("b_1", fit.b[0], fit.ci_b[0], fit.b_fixed[0]) + ",  " +
              exponent_text("b_2", fit.b[1], fit.ci_b[1], fit.b_fixed[1]),
          std::string(c.two_regimes_warranted ? "two regimes: " : "one regime suffices: ") + test +
              ",  ΔAIC = " + fixed(c.aic_broken - c.aic_single, 1)};
}

// Annotations go in a corner the legend does not use: bottom right, or top left when the
// legend sits at the bottom (rising data leave those corners empty most often).
void add_annotations(Figure& figure, const std::vector<std::string>& lines, LegendPosition legend) {
  const bool legend_at_bottom =
      legend == LegendPosition::lower_left || legend == LegendPosition::lower_right;
  const double step = 0.07;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const double k = static_cast<double>(i);
    if (legend_at_bottom) {
      figure.add_text_in_axes(0.03, 0.93 - k * step, lines[i],
                              {9.5, kFitLine, TextAnchor::left, true});
    } else {
      const double from_bottom = static_cast<double>(lines.size() - 1) - k;
      figure.add_text_in_axes(0.97, 0.05 + from_bottom * step, lines[i],
                              {9.5, kFitLine, TextAnchor::right, true});
    }
  }
}

// With the legend in the upper left, a point high on the left would hide under it. The legend
// box is estimated (its height grows with the entries: groups, missing-value reasons, and the
// fit's line, band and breakpoint); when a point's marker or quartile bar reaches into it, the
// top of the y axis is raised so that every point lies below the box.
void keep_points_clear_of_legend(Figure& figure, const std::vector<RegimePoint>& points,
                                 std::size_t entries, const RegimeDiagramOptions& options) {
  if (options.legend != LegendPosition::upper_left) return;
  double x_lo = INFINITY, x_hi = -INFINITY, y_lo = INFINITY, y_hi = -INFINITY;
  for (const RegimePoint& p : points) {
    x_lo = std::min(x_lo, std::log10(p.pi));
    x_hi = std::max(x_hi, std::log10(p.pi));
    if (p.failed) continue;
    const double top = std::isfinite(p.y_q75) ? std::max(p.y, p.y_q75) : p.y;
    const double bottom = std::isfinite(p.y_q25) ? std::min(p.y, p.y_q25) : p.y;
    y_lo = std::min(y_lo, std::log10(bottom));
    y_hi = std::max(y_hi, std::log10(top));
  }
  if (!(y_hi > y_lo) || !(x_hi > x_lo)) return;
  const double box_height = std::min(0.7, 0.04 + 0.065 * static_cast<double>(entries + 1));
  const double box_width = 0.45;
  bool covered = false;
  for (const RegimePoint& p : points) {
    if (p.failed) continue;
    const double fx = (std::log10(p.pi) - x_lo) / (x_hi - x_lo);
    const double top = std::isfinite(p.y_q75) ? std::max(p.y, p.y_q75) : p.y;
    const double fy = (std::log10(top) - y_lo) / (y_hi - y_lo);
    if (fx < box_width && fy > 1.0 - box_height - 0.05) covered = true;
  }
  if (!covered) return;
  const double top = y_lo + (y_hi - y_lo) / (1.0 - box_height);
  figure.set_y_axis(options.y_label, AxisScale::log10, std::nullopt, std::pow(10.0, top));
}

}  // namespace

Figure regime_diagram(const std::vector<RegimePoint>& points, const RegimeFit& fit,
                      const RegimeDiagramOptions& options) {
  if (points.empty() && std::holds_alternative<std::monostate>(fit)) {
    throw std::invalid_argument("regime diagram: no points and no fit; nothing to draw");
  }
  // Groups in order of first appearance, so colours follow the caller's ordering.
  std::vector<std::string> groups;
  for (const RegimePoint& p : points) {
    if (std::find(groups.begin(), groups.end(), p.group) == groups.end()) groups.push_back(p.group);
  }
  // A legend of more than 7 entries (groups, missing-value reasons, the fit's 2 or 4) would
  // cover the data: it goes beside the axes, on a figure widened to keep the axes' size.
  // Points without a value after all groups, so the legend lists the groups first; one
  // marker shape per reason, the colour of the point's group.
  std::vector<std::string> reasons;
  for (const RegimePoint& p : points) {
    if (p.failed && std::find(reasons.begin(), reasons.end(), p.missing_reason) == reasons.end())
      reasons.push_back(p.missing_reason);
  }
  const std::size_t fit_entries = (std::holds_alternative<BrokenLineFit>(fit)  ? 4
                                   : std::holds_alternative<PowerLawFit>(fit) ? 2
                                                                              : 0) +
                                  options.references.size() + (options.shade_below.empty() ? 0 : 1);
  RegimeDiagramOptions layout = options;
  if (options.legend == LegendPosition::upper_left &&
      groups.size() + reasons.size() + fit_entries > 7) {
    layout.legend = LegendPosition::outside_right;
    layout.width_pt += 190.0;
  }
  Figure figure(layout.width_pt, layout.height_pt);
  figure.set_title(options.title);
  figure.set_x_axis(options.x_label, AxisScale::log10);
  figure.set_y_axis(options.y_label, AxisScale::log10);
  figure.set_legend_position(layout.legend);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const RegimePoint& p = points[i];
    if (!std::isfinite(p.pi) || p.pi <= 0.0 || (!p.failed && (!std::isfinite(p.y) || p.y <= 0.0))) {
      throw std::invalid_argument("regime diagram: point " + std::to_string(i) +
                                  " (Π = " + std::to_string(p.pi) + ", y = " + std::to_string(p.y) +
                                  ") cannot go on log axes; mark cases without a "
                                  "value as failed, and check Π > 0");
    }
  }

  if (!options.shade_below.empty()) {
    double x_min = HUGE_VAL;
    for (const RegimePoint& p : points) x_min = std::min(x_min, p.pi);
    bool named = false;
    for (double x : options.shade_below) {
      if (!(x > x_min)) continue;
      figure.add_vertical_band(x_min, x, kUnderResolvedBand, named ? "" : options.shade_legend);
      named = true;
    }
  }
  for (const ReferenceCurve& r : options.references)
    figure.add_line(r.x, r.y, {kReferenceLine, 1.2, {5.0, 3.0}}, r.legend);

  std::vector<std::string> annotations;
  if (const auto* power = std::get_if<PowerLawFit>(&fit)) {
    annotations = add_power_law(figure, *power, options);
  }
  if (const auto* broken = std::get_if<BrokenLineFit>(&fit)) {
    annotations = add_broken_line(figure, *broken, options);
  }

  std::vector<std::string> hollow_reasons;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    std::vector<double> x, y, x_bar, lo, hi;
    std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> hollow;
    for (const RegimePoint& p : points) {
      if (p.group != groups[g]) continue;
      if (p.failed) continue;
      if (p.hollow) {
        hollow[p.hollow_reason].first.push_back(p.pi);
        hollow[p.hollow_reason].second.push_back(p.y);
      } else {
        x.push_back(p.pi);
        y.push_back(p.y);
      }
      if (std::isfinite(p.y_q25) && std::isfinite(p.y_q75)) {
        x_bar.push_back(p.pi);
        lo.push_back(p.y_q25);
        hi.push_back(p.y_q75);
      }
    }
    const Color color = palette_color(g);
    figure.add_error_bars(x_bar, lo, hi, color.with_alpha(0.8));
    figure.add_points(x, y, {palette_marker(g), color, 6.5, true},
                      groups[g].empty() ? "cases" : groups[g]);
    for (const auto& [reason, xy] : hollow) {
      const bool named =
          std::find(hollow_reasons.begin(), hollow_reasons.end(), reason) != hollow_reasons.end();
      if (!named) hollow_reasons.push_back(reason);
      figure.add_points(xy.first, xy.second, {palette_marker(g), color, 6.5, false},
                        named ? "" : reason);
    }
  }
  constexpr MarkerShape kMissingShapes[] = {MarkerShape::cross, MarkerShape::plus,
                                            MarkerShape::circle, MarkerShape::square,
                                            MarkerShape::diamond};
  for (std::size_t r = 0; r < reasons.size(); ++r) {
    bool in_legend = false;
    for (std::size_t g = 0; g < groups.size(); ++g) {
      std::vector<double> x;
      for (const RegimePoint& p : points) {
        if (p.failed && p.group == groups[g] && p.missing_reason == reasons[r]) x.push_back(p.pi);
      }
      if (x.empty()) continue;
      figure.add_bottom_markers(
          x, {kMissingShapes[r % std::size(kMissingShapes)], palette_color(g), 6.0, false},
          in_legend ? "" : reasons[r]);
      in_legend = true;
    }
  }
  add_annotations(figure, annotations, layout.legend);
  keep_points_clear_of_legend(figure, points,
                              groups.size() + reasons.size() + hollow_reasons.size() + fit_entries,
                              layout);
  return figure;
}

Figure empirical_cdf_figure(const std::vector<NamedSample>& samples,
                            const CdfFigureOptions& options) {
  if (samples.empty()) {
    throw std::invalid_argument("CDF figure: no samples given; pass at least one named sample");
  }
  Figure figure(options.width_pt, options.height_pt);
  figure.set_title(options.title);
  figure.set_x_axis(options.x_label, options.x_scale);
  figure.set_y_axis(options.y_label, AxisScale::linear, 0.0, 1.0);
  figure.set_legend_position(options.legend);
  for (std::size_t s = 0; s < samples.size(); ++s) {
    const NamedSample& sample = samples[s];
    if (sample.values.empty()) {
      throw std::invalid_argument("CDF figure: sample '" + sample.name +
                                  "' is empty; drop it or give it values");
    }
    for (std::size_t i = 0; i < sample.values.size(); ++i) {
      const double v = sample.values[i];
      if (!std::isfinite(v) || (options.x_scale == AxisScale::log10 && v <= 0.0)) {
        throw std::invalid_argument(
            "CDF figure: sample '" + sample.name + "' value " + std::to_string(i) + " = " +
            std::to_string(v) + (std::isfinite(v) ? " cannot go on a log axis" : " is not finite"));
      }
    }
    std::vector<double> sorted = sample.values;
    std::sort(sorted.begin(), sorted.end());
    // F̂(x) = #{x_i ≤ x}/n as a right-continuous staircase.
    const double n = static_cast<double>(sorted.size());
    std::vector<double> x{sorted.front()}, y{0.0};
    for (std::size_t i = 0; i < sorted.size(); ++i) {
      x.push_back(sorted[i]);
      y.push_back(static_cast<double>(i + 1) / n);
      if (i + 1 < sorted.size()) {
        x.push_back(sorted[i + 1]);
        y.push_back(static_cast<double>(i + 1) / n);
      }
    }
    figure.add_line(x, y, {palette_color(s), 1.6, {}},
                    sample.name + " (n = " + std::to_string(sorted.size()) + ")");
  }
  return figure;
}

ReferenceCurve nye_zero_stress_depth(double pi_lo, double pi_hi, int points) {
  if (!(pi_lo > 0.0) || !(pi_hi >= pi_lo) || !std::isfinite(pi_hi) || points < 1)
    throw std::invalid_argument("Nye's depth needs 0 < Π_lo <= Π_hi and at least one point");
  ReferenceCurve nye{"Nye's zero-stress depth, D_p/H_i = 2Π", {}, {}};
  for (int i = 0; i <= points; ++i) {
    const double x = pi_lo * std::pow(pi_hi / pi_lo, static_cast<double>(i) / points);
    nye.x.push_back(x);
    nye.y.push_back(std::min(1.0, 2.0 * x));
  }
  return nye;
}

}  // namespace crevasse::analysis
