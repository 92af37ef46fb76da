#pragma once
// A small 2D plotting layer on cairo for the study figures: linear or log10 axes, markers,
// error bars, lines, shaded bands, text, legend and title. One drawing routine renders both
// the PNG and the SVG, so the two always agree, and the same figure always gives the same bytes.
//
// Text takes a tiny markup for symbols: "_x" or "_{..}" sets a subscript, "^x" or "^{..}" a
// superscript, "\\" escapes the next character. E.g. "L_p/H_i", "10^{-2}", "Π = c/(ρ_i g H_i)".
#include <cstddef>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace crevasse::analysis {

struct Color {
  double r = 0.0, g = 0.0, b = 0.0, a = 1.0;
  Color with_alpha(double alpha) const { return {r, g, b, alpha}; }
};

// The Okabe–Ito colour-blind-safe qualitative palette (Okabe & Ito 2008), cycled by index.
Color palette_color(std::size_t index);

enum class AxisScale { linear, log10 };
enum class MarkerShape { circle, square, triangle_up, triangle_down, diamond, cross, plus };
// Filled shapes first, cycled by index, so groups differ in shape as well as colour.
MarkerShape palette_marker(std::size_t index);

struct MarkerStyle {
  MarkerShape shape = MarkerShape::circle;
  Color color;
  double size_pt = 6.0;  // outer diameter
  bool filled = true;    // hollow when false (cross and plus are always strokes)
};

struct LineStyle {
  Color color;
  double width_pt = 1.5;
  std::vector<double> dash_pt;  // empty: solid
};

// outside_right: beside the axes, which give up the legend's width (for long legends).
enum class LegendPosition { upper_left, upper_right, lower_left, lower_right, none, outside_right };
enum class TextAnchor { left, centre, right };

// `text` escaped so that figure text shows it literally (names of studies, files, ...).
std::string escape_markup(const std::string& text);

struct TextStyle {
  double size_pt = 10.0;
  Color color;
  TextAnchor anchor = TextAnchor::left;
  bool boxed = false;  // on a translucent white backing
};

class Figure {
 public:
  explicit Figure(double width_pt = 480.0, double height_pt = 360.0);

  void set_title(std::string title) { title_ = std::move(title); }
  // An axis range left empty is taken from the data (padded; log axes use positive data only).
  void set_x_axis(std::string label, AxisScale scale, std::optional<double> min = std::nullopt,
                  std::optional<double> max = std::nullopt);
  void set_y_axis(std::string label, AxisScale scale, std::optional<double> min = std::nullopt,
                  std::optional<double> max = std::nullopt);
  void set_legend_position(LegendPosition position) { legend_position_ = position; }

  // Every add_* with a non-empty `legend` adds a legend entry in call order. Sizes of x and
  // the y vectors must match (std::invalid_argument otherwise); non-finite values, and
  // non-positive values on a log axis, are skipped when drawing.
  void add_points(std::vector<double> x, std::vector<double> y, MarkerStyle style,
                  std::string legend = {});
  // Markers on the bottom edge of the plot at the given x: cases without a y (e.g. failed).
  void add_bottom_markers(std::vector<double> x, MarkerStyle style, std::string legend = {});
  void add_error_bars(std::vector<double> x, std::vector<double> y_low, std::vector<double> y_high,
                      Color color, double width_pt = 0.8);
  void add_line(std::vector<double> x, std::vector<double> y, LineStyle style,
                std::string legend = {});
  // Filled region between y_low(x) and y_high(x).
  void add_band(std::vector<double> x, std::vector<double> y_low, std::vector<double> y_high,
                Color fill, std::string legend = {});
  // Full-height shaded band x_low ≤ x ≤ x_high (e.g. a breakpoint interval).
  void add_vertical_band(double x_low, double x_high, Color fill, std::string legend = {});
  void add_vertical_line(double x, LineStyle style, std::string legend = {});
  // Text at data coordinates, or at axes fractions (0,0 bottom-left, 1,1 top-right).
  void add_text(double x, double y, std::string text, TextStyle style = {});
  void add_text_in_axes(double fx, double fy, std::string text, TextStyle style = {});

  double width_pt() const { return width_pt_; }
  double height_pt() const { return height_pt_; }

  // PNG at `pixels_per_pt` (2 gives 144 dpi). Throws std::runtime_error naming the path when
  // the file cannot be written.
  void write_png(const std::string& path, double pixels_per_pt = 2.0) const;
  void write_svg(const std::string& path) const;
  // The SVG document, with the figure's text also in <title>/<desc>, markup as written (cairo
  // draws glyphs as outlines, so this is what makes the text searchable).
  std::string svg() const;

  struct AxisSpec {
    std::string label;
    AxisScale scale = AxisScale::linear;
    std::optional<double> min, max;
  };
  struct Points {
    std::vector<double> x, y;
    MarkerStyle style;
  };
  struct BottomMarkers {
    std::vector<double> x;
    MarkerStyle style;
  };
  struct ErrorBars {
    std::vector<double> x, y_low, y_high;
    Color color;
    double width_pt;
  };
  struct Line {
    std::vector<double> x, y;
    LineStyle style;
  };
  struct Band {
    std::vector<double> x, y_low, y_high;
    Color fill;
  };
  struct VerticalBand {
    double x_low, x_high;
    Color fill;
  };
  struct VerticalLine {
    double x;
    LineStyle style;
  };
  struct Text {
    double x, y;
    bool in_axes;
    std::string text;
    TextStyle style;
  };
  using Item =
      std::variant<Points, BottomMarkers, ErrorBars, Line, Band, VerticalBand, VerticalLine, Text>;
  struct LegendEntry {
    std::string label;
    std::size_t item;  // index into items()
  };
  const std::vector<Item>& items() const { return items_; }
  const std::vector<LegendEntry>& legend() const { return legend_; }
  const std::string& title() const { return title_; }
  const AxisSpec& x_axis() const { return x_axis_; }
  const AxisSpec& y_axis() const { return y_axis_; }
  LegendPosition legend_position() const { return legend_position_; }

 private:
  void add(Item item, std::string legend);

  double width_pt_, height_pt_;
  std::string title_;
  AxisSpec x_axis_, y_axis_;
  LegendPosition legend_position_ = LegendPosition::upper_left;
  std::vector<Item> items_;
  std::vector<LegendEntry> legend_;
};

}  // namespace crevasse::analysis
