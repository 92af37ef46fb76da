// The cairo plotting layer and the study figures built on it: files are written, the SVG
// carries the figure's text, and the same input gives the same bytes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "analysis/plot.hpp"
#include "analysis/regime_diagram.hpp"

namespace crevasse::analysis {
namespace {

std::filesystem::path output_dir() {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "crevasse_plot";
  std::filesystem::create_directories(dir);
  return dir;
}

std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

Figure every_item_figure() {
  Figure figure(420.0, 300.0);
  figure.set_title("All items");
  figure.set_x_axis("Π = c/(ρ_i g H_i)", AxisScale::log10);
  figure.set_y_axis("L_p/H_i", AxisScale::log10);
  const std::vector<double> x{0.01, 0.03, 0.1, 0.3, 1.0};
  const std::vector<double> y{0.2, 0.35, 0.6, 1.1, 2.0};
  figure.add_vertical_band(0.05, 0.2, palette_color(4).with_alpha(0.2), "interval");
  figure.add_band(x, {0.15, 0.3, 0.5, 0.9, 1.6}, {0.25, 0.4, 0.7, 1.3, 2.4}, {0.5, 0.5, 0.5, 0.25},
                  "band");
  figure.add_error_bars(x, {0.18, 0.3, 0.5, 1.0, 1.8}, {0.22, 0.4, 0.7, 1.2, 2.2},
                        palette_color(0));
  figure.add_line(x, y, {palette_color(7), 1.5, {}}, "line");
  figure.add_vertical_line(0.1, {palette_color(1), 1.0, {3.0, 2.0}});
  for (int shape = 0; shape < 7; ++shape) {
    figure.add_points({0.02 * (shape + 1)}, {0.3 + 0.1 * shape},
                      {static_cast<MarkerShape>(shape), palette_color(shape), 7.0, shape % 2 == 0},
                      "shape " + std::to_string(shape));
  }
  figure.add_bottom_markers({0.5}, {MarkerShape::cross, palette_color(1), 6.0, false}, "failed");
  figure.add_text(0.3, 1.5, "b = 0.5", {});
  figure.add_text_in_axes(0.95, 0.05, "note in axes", {9.0, {}, TextAnchor::right});
  return figure;
}

TEST(PlotFigure, WritesPngAndSvgWithTheFigureText) {
  const Figure figure = every_item_figure();
  const std::filesystem::path png = output_dir() / "every_item.png";
  const std::filesystem::path svg = output_dir() / "every_item.svg";
  figure.write_png(png.string());
  figure.write_svg(svg.string());
  const std::string png_bytes = read_bytes(png);
  ASSERT_GT(png_bytes.size(), 1000u);  // a blank 840×600 PNG alone is ~ 2 kB; any drawing adds
  EXPECT_EQ(png_bytes.substr(1, 3), "PNG");
  const std::string svg_text = read_bytes(svg);
  EXPECT_TRUE(contains(svg_text, "<svg"));
  EXPECT_TRUE(contains(svg_text, "<title>All items</title>"));
  EXPECT_TRUE(contains(svg_text, "L_p/H_i"));
  EXPECT_TRUE(contains(svg_text, "Π = c/(ρ_i g H_i)"));
  EXPECT_TRUE(contains(svg_text, "note in axes"));
  EXPECT_TRUE(contains(svg_text, "legend: failed"));
}

TEST(PlotFigure, SameFigureGivesIdenticalBytes) {
  const std::string first = every_item_figure().svg();
  // Another figure in between advances cairo's process-wide surface counter.
  (void)Figure(200.0, 150.0).svg();
  const std::string second = every_item_figure().svg();
  EXPECT_EQ(first, second);
  const std::filesystem::path a = output_dir() / "same_a.png", b = output_dir() / "same_b.png";
  every_item_figure().write_png(a.string());
  every_item_figure().write_png(b.string());
  EXPECT_EQ(read_bytes(a), read_bytes(b));
}

TEST(PlotFigure, BadInputsAreRejectedClearly) {
  Figure figure;
  EXPECT_THROW(figure.add_points({1.0, 2.0}, {1.0}, {}), std::invalid_argument);
  EXPECT_THROW(figure.add_band({1.0, 2.0}, {1.0, 2.0}, {1.0}, {}), std::invalid_argument);
  EXPECT_THROW(Figure(0.0, 100.0), std::invalid_argument);
  Figure bad_range;
  bad_range.set_x_axis("x", AxisScale::log10, -1.0, 10.0);
  EXPECT_THROW(bad_range.svg(), std::invalid_argument);
  EXPECT_THROW(every_item_figure().write_png("/nonexistent-folder/figure.png"), std::runtime_error);
  EXPECT_THROW(every_item_figure().write_svg("/nonexistent-folder/figure.svg"), std::runtime_error);
}

std::vector<RegimePoint> two_regime_points() {
  // L/H = 2·(Π/0.1)^b with b = 1 below Π* = 0.1 and 0.25 above; two thickness groups.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.08);
  std::vector<RegimePoint> points;
  for (int i = 0; i < 30; ++i) {
    const double pi = std::pow(10.0, -2.5 + 2.5 * i / 29.0);
    const double y = 2.0 * std::pow(pi / 0.1, pi < 0.1 ? 1.0 : 0.25) * std::exp(noise(rng));
    points.push_back({pi, y, 0.8 * y, 1.25 * y, i % 2 ? "H_i = 200 m" : "H_i = 400 m", false});
  }
  points.push_back({0.002, 0.0, 0.0, 0.0, "H_i = 200 m", true});
  return points;
}

TEST(RegimeDiagram, DrawsBrokenLineWithBreakpointBandAndFailedCases) {
  const std::vector<RegimePoint> points = two_regime_points();
  std::vector<double> pi, y;
  for (const RegimePoint& p : points) {
    if (!p.failed) {
      pi.push_back(p.pi);
      y.push_back(p.y);
    }
  }
  RegimeDiagramOptions options;
  options.title = "Spacing regimes";
  const Figure figure = regime_diagram(points, fit_broken_line(pi, y), options);
  figure.write_png((output_dir() / "regime_broken.png").string());
  const std::string svg = figure.svg();
  EXPECT_TRUE(contains(svg, "Π^* = "));
  EXPECT_TRUE(contains(svg, "b_1 = "));
  EXPECT_TRUE(contains(svg, "two regimes"));
  EXPECT_TRUE(contains(svg, "legend: failed / no crevasse"));
  EXPECT_TRUE(contains(svg, "legend: H_i = 400 m"));
  EXPECT_EQ(svg, regime_diagram(points, fit_broken_line(pi, y), options).svg());
  // The failed case is drawn, not dropped: it is one of the figure's items.
  int bottom_markers = 0;
  for (const Figure::Item& item : figure.items()) {
    bottom_markers += std::holds_alternative<Figure::BottomMarkers>(item);
  }
  EXPECT_EQ(bottom_markers, 1);
}

TEST(RegimeDiagram, DrawsASinglePowerLaw) {
  std::vector<RegimePoint> points;
  std::vector<double> pi, y;
  for (int i = 0; i < 12; ++i) {
    pi.push_back(std::pow(10.0, -2.0 + 2.0 * i / 11.0));
    y.push_back(0.7 * std::pow(pi.back(), 0.5) * (1.0 + 0.05 * ((i % 3) - 1)));
    points.push_back({pi.back(), y.back(), 0.9 * y.back(), 1.1 * y.back(), "", false});
  }
  RegimeDiagramOptions options;
  options.y_label = "D_p/H_i";
  const Figure figure = regime_diagram(points, fit_power_law(pi, y), options);
  figure.write_png((output_dir() / "regime_single.png").string());
  const std::string svg = figure.svg();
  EXPECT_TRUE(contains(svg, "D_p/H_i = "));
  EXPECT_TRUE(contains(svg, "R^2 = "));
  EXPECT_THROW(regime_diagram({}), std::invalid_argument);
  EXPECT_THROW(regime_diagram({{-1.0, 1.0, 1.0, 1.0, "", false}}), std::invalid_argument);
  EXPECT_THROW(regime_diagram({{0.1, 0.0, 1.0, 1.0, "", false}}), std::invalid_argument);
}

TEST(RegimeCdf, DrawsOneStaircasePerSample) {
  const std::vector<NamedSample> samples{{"dx = 10 m", {40.0, 55.0, 61.0, 70.0, 90.0}},
                                         {"dx = 5 m", {35.0, 48.0, 52.0, 66.0}}};
  CdfFigureOptions options;
  options.title = "Spacing distributions";
  const Figure figure = empirical_cdf_figure(samples, options);
  figure.write_png((output_dir() / "cdf.png").string());
  const std::string svg = figure.svg();
  EXPECT_TRUE(contains(svg, "legend: dx = 10 m (n = 5)"));
  EXPECT_TRUE(contains(svg, "legend: dx = 5 m (n = 4)"));
  EXPECT_THROW(empirical_cdf_figure({}), std::invalid_argument);
  EXPECT_THROW(empirical_cdf_figure({{"empty", {}}}), std::invalid_argument);
  EXPECT_THROW(empirical_cdf_figure({{"nan", {1.0, std::nan("")}}}), std::invalid_argument);
}

// Legend placement: a point high on the left lifts the top of the y axis clear of the
// upper-left legend; a legend of more than 7 entries moves beside the axes on a wider figure;
// a diagram with neither keeps the automatic range and the default width.
TEST(RegimeDiagram, LegendKeepsClearOfThePoints) {
  RegimeDiagramOptions options;
  std::vector<RegimePoint> low_left = {{0.1, 1.0, NAN, NAN, "a"}, {1.0, 2.0, NAN, NAN, "a"}};
  const Figure plain = regime_diagram(low_left, {}, options);
  EXPECT_FALSE(plain.y_axis().max.has_value());
  EXPECT_EQ(plain.legend_position(), LegendPosition::upper_left);
  EXPECT_DOUBLE_EQ(plain.width_pt(), options.width_pt);

  std::vector<RegimePoint> high_left = {{0.1, 2.0, NAN, NAN, "a"}, {1.0, 1.0, NAN, NAN, "a"}};
  const Figure lifted = regime_diagram(high_left, {}, options);
  ASSERT_TRUE(lifted.y_axis().max.has_value());
  // The high point must end up below a one-group legend (a row of about 6.5 % of the axes'
  // height, plus padding): at most 85 % of the way up the log axis from the lowest point.
  const double fy = std::log10(2.0 / 1.0) / std::log10(*lifted.y_axis().max / 1.0);
  EXPECT_LT(fy, 0.85);

  std::vector<RegimePoint> many;
  for (int g = 0; g < 8; ++g)
    many.push_back({0.1 * (g + 1), 1.0 + 0.1 * g, NAN, NAN, "group " + std::to_string(g)});
  const Figure wide = regime_diagram(many, {}, options);
  EXPECT_EQ(wide.legend_position(), LegendPosition::outside_right);
  EXPECT_GT(wide.width_pt(), options.width_pt);
  EXPECT_FALSE(wide.y_axis().max.has_value());
  const auto png = std::filesystem::temp_directory_path() / "crevasse_legend_outside.png";
  wide.write_png(png.string());
  EXPECT_GT(std::filesystem::file_size(png), 1000u);
  std::filesystem::remove(png);
}

}  // namespace
}  // namespace crevasse::analysis
