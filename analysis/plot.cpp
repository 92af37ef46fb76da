#include "analysis/plot.hpp"

#include <cairo-svg.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <numbers>
#include <regex>
#include <stdexcept>

#include "analysis/cairo_canvas.hpp"
#include "engine/atomic_file.hpp"

namespace crevasse::analysis {
namespace {

using canvas::segment;
using canvas::set_color;

constexpr const char* kFontFamily = "sans-serif";
constexpr double kTickFontPt = 9.0;
constexpr double kLabelFontPt = 11.0;
constexpr double kTitleFontPt = 12.0;
constexpr double kLegendFontPt = 9.0;
const Color kBlack{0.0, 0.0, 0.0, 1.0};
const Color kGrid{0.88, 0.88, 0.88, 1.0};

// ---- Text with sub/superscripts -------------------------------------------------------------

struct TextRun {
  std::string text;
  int level = 0;  // −1 subscript, 0 normal, +1 superscript
};

std::size_t utf8_length(unsigned char lead) {
  if (lead < 0x80) return 1;
  if ((lead >> 5) == 0x6) return 2;
  if ((lead >> 4) == 0xE) return 3;
  return 4;
}

std::vector<TextRun> parse_markup(const std::string& text) {
  std::vector<TextRun> runs{{"", 0}};
  const auto append = [&](const std::string& piece, int level) {
    if (runs.back().level != level) runs.push_back({"", level});
    runs.back().text += piece;
  };
  for (std::size_t i = 0; i < text.size();) {
    const char c = text[i];
    if (c == '\\' && i + 1 < text.size()) {
      const std::size_t n = utf8_length(static_cast<unsigned char>(text[i + 1]));
      append(text.substr(i + 1, n), 0);
      i += 1 + n;
    } else if ((c == '_' || c == '^') && i + 1 < text.size()) {
      const int level = c == '_' ? -1 : 1;
      if (text[i + 1] == '{') {
        const std::size_t close = text.find('}', i + 2);
        const std::size_t end = close == std::string::npos ? text.size() : close;
        append(text.substr(i + 2, end - i - 2), level);
        i = end + 1;
      } else {
        const std::size_t n = utf8_length(static_cast<unsigned char>(text[i + 1]));
        append(text.substr(i + 1, n), level);
        i += 1 + n;
      }
    } else {
      const std::size_t n = utf8_length(static_cast<unsigned char>(c));
      append(text.substr(i, n), 0);
      i += n;
    }
  }
  return runs;
}

double run_size(double size_pt, int level) { return level == 0 ? size_pt : 0.7 * size_pt; }
double run_rise(double size_pt, int level) {
  return level < 0 ? 0.22 * size_pt : level > 0 ? -0.38 * size_pt : 0.0;
}

double text_width(cairo_t* cr, const std::string& text, double size_pt) {
  double width = 0.0;
  for (const TextRun& run : parse_markup(text)) {
    cairo_set_font_size(cr, run_size(size_pt, run.level));
    cairo_text_extents_t extents;
    cairo_text_extents(cr, run.text.c_str(), &extents);
    width += extents.x_advance;
  }
  return width;
}

// Draws with the baseline at y and the anchor at x.
void draw_text(cairo_t* cr, double x, double y, const std::string& text, const TextStyle& style) {
  const double width = text_width(cr, text, style.size_pt);
  double pen = style.anchor == TextAnchor::left     ? x
               : style.anchor == TextAnchor::centre ? x - 0.5 * width
                                                    : x - width;
  cairo_set_source_rgba(cr, style.color.r, style.color.g, style.color.b, style.color.a);
  for (const TextRun& run : parse_markup(text)) {
    cairo_set_font_size(cr, run_size(style.size_pt, run.level));
    cairo_move_to(cr, pen, y + run_rise(style.size_pt, run.level));
    cairo_show_text(cr, run.text.c_str());
    cairo_text_extents_t extents;
    cairo_text_extents(cr, run.text.c_str(), &extents);
    pen += extents.x_advance;
  }
}

// ---- Axes -----------------------------------------------------------------------------------

struct Tick {
  double value;
  std::string label;  // empty: minor tick
};

std::string number_label(double value, double step) {
  // Enough decimals to tell ticks `step` apart; snap tiny values (round-off of 0) to 0.
  if (std::abs(value) < 1e-9 * step) value = 0.0;
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  char buffer[64];
  if (std::abs(value) >= 1e5 || (value != 0.0 && std::abs(value) < 1e-3)) {
    std::snprintf(buffer, sizeof buffer, "%.3g", value);
  } else {
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  }
  return buffer;
}

double nice_step(double span, int target_ticks) {
  const double raw = span / target_ticks;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double factor : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (factor * magnitude >= raw) return factor * magnitude;
  }
  return 10.0 * magnitude;
}

std::vector<Tick> linear_ticks(double lo, double hi) {
  const double step = nice_step(hi - lo, 5);
  std::vector<Tick> ticks;
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k += 1.0) {
    ticks.push_back({k * step, number_label(k * step, step)});
  }
  return ticks;
}

std::vector<Tick> log_ticks(double lo, double hi) {
  const int first = static_cast<int>(std::floor(std::log10(lo) + 1e-9));
  const int last = static_cast<int>(std::ceil(std::log10(hi) - 1e-9));
  std::vector<Tick> ticks;
  if (last - first < 2) {
    // Less than about a decade: decades alone would leave the axis unlabelled.
    for (Tick tick : linear_ticks(lo, hi)) {
      if (tick.value > 0.0) ticks.push_back(tick);
    }
    return ticks;
  }
  const int every = (last - first) > 8 ? 2 : 1;  // keep labels from colliding
  // With fewer than three decades shown, decade labels alone leave the axis hard to read:
  // label 1, 2 and 5 of each decade as plain numbers instead.
  const bool sparse = last - first < 4;
  for (int k = first; k <= last; ++k) {
    const double decade = std::pow(10.0, k);
    if (decade >= lo * (1 - 1e-9) && decade <= hi * (1 + 1e-9)) {
      const std::string label = sparse           ? number_label(decade, decade)
                                : k % every == 0 ? "10^{" + std::to_string(k) + "}"
                                                 : "";
      ticks.push_back({decade, label});
    }
    for (int m = 2; m <= 9; ++m) {
      const double minor = m * decade;
      const bool labelled = sparse && (m == 2 || m == 5);
      if (minor >= lo && minor <= hi)
        ticks.push_back({minor, labelled ? number_label(minor, decade) : ""});
    }
  }
  // A range that straddles a decade but spans little of either side (e.g. 0.6 to 1.2) would
  // show one label: label it linearly instead.
  const auto labelled = std::count_if(ticks.begin(), ticks.end(),
                                      [](const Tick& t) { return !t.label.empty(); });
  if (labelled < 3) {
    ticks.clear();
    for (Tick tick : linear_ticks(lo, hi))
      if (tick.value > 0.0) ticks.push_back(tick);
  }
  return ticks;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void include(double v, AxisScale scale) {
    if (!std::isfinite(v) || (scale == AxisScale::log10 && v <= 0.0)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
};

class AxisMap {
 public:
  AxisMap(const Figure::AxisSpec& spec, Range data) : scale_(spec.scale) {
    const bool log = scale_ == AxisScale::log10;
    if (!(data.lo <= data.hi)) data = log ? Range{1.0, 10.0} : Range{0.0, 1.0};
    double lo = forward(data.lo), hi = forward(data.hi);
    if (hi - lo < 1e-12 * (1.0 + std::abs(lo))) {  // one value: open a unit window around it
      lo -= log ? 0.5 : 0.5 * std::max(std::abs(lo), 1.0);
      hi += log ? 0.5 : 0.5 * std::max(std::abs(hi), 1.0);
    }
    const double pad = 0.05 * (hi - lo);
    lo_ = spec.min ? forward(*spec.min) : lo - pad;
    hi_ = spec.max ? forward(*spec.max) : hi + pad;
    if (!(lo_ < hi_) || !std::isfinite(lo_) || !std::isfinite(hi_)) {
      throw std::invalid_argument("figure axis '" + spec.label +
                                  "': the range is empty or invalid "
                                  "(min must be below max, and positive on a log axis)");
    }
  }
  double forward(double v) const { return scale_ == AxisScale::log10 ? std::log10(v) : v; }
  // Fraction of the axis length, 0 at the low end.
  double fraction(double v) const { return (forward(v) - lo_) / (hi_ - lo_); }
  double min() const { return inverse(lo_); }
  double max() const { return inverse(hi_); }
  bool drawable(double v) const {
    return std::isfinite(v) && (scale_ != AxisScale::log10 || v > 0.0);
  }
  std::vector<Tick> ticks() const {
    return scale_ == AxisScale::log10 ? log_ticks(min(), max()) : linear_ticks(min(), max());
  }

 private:
  double inverse(double t) const { return scale_ == AxisScale::log10 ? std::pow(10.0, t) : t; }
  AxisScale scale_;
  double lo_ = 0.0, hi_ = 1.0;
};

Range data_range(const std::vector<Figure::Item>& items, bool x_axis, AxisScale scale) {
  Range range;
  const auto add_all = [&](const std::vector<double>& values) {
    for (double v : values) range.include(v, scale);
  };
  for (const Figure::Item& item : items) {
    std::visit(
        [&](const auto& it) {
          using T = std::decay_t<decltype(it)>;
          if constexpr (std::is_same_v<T, Figure::Points> || std::is_same_v<T, Figure::Line>) {
            add_all(x_axis ? it.x : it.y);
          } else if constexpr (std::is_same_v<T, Figure::ErrorBars> ||
                               std::is_same_v<T, Figure::Band>) {
            if (x_axis) {
              add_all(it.x);
            } else {
              add_all(it.y_low);
              add_all(it.y_high);
            }
          } else if constexpr (std::is_same_v<T, Figure::BottomMarkers>) {
            if (x_axis) add_all(it.x);
          } else if constexpr (std::is_same_v<T, Figure::VerticalBand>) {
            if (x_axis) {
              range.include(it.x_low, scale);
              range.include(it.x_high, scale);
            }
          } else if constexpr (std::is_same_v<T, Figure::VerticalLine>) {
            if (x_axis) range.include(it.x, scale);
          }
        },
        item);
  }
  return range;
}

// ---- Primitives -----------------------------------------------------------------------------

void apply_line_style(cairo_t* cr, const LineStyle& style) {
  set_color(cr, style.color);
  cairo_set_line_width(cr, style.width_pt);
  cairo_set_dash(cr, style.dash_pt.data(), static_cast<int>(style.dash_pt.size()), 0.0);
}

void draw_marker(cairo_t* cr, double x, double y, const MarkerStyle& style) {
  const double r = 0.5 * style.size_pt;
  cairo_new_path(cr);
  switch (style.shape) {
    case MarkerShape::circle:
      cairo_arc(cr, x, y, r, 0.0, 2.0 * std::numbers::pi);
      break;
    case MarkerShape::square:
      cairo_rectangle(cr, x - 0.85 * r, y - 0.85 * r, 1.7 * r, 1.7 * r);
      break;
    case MarkerShape::triangle_up:
    case MarkerShape::triangle_down: {
      const double s = style.shape == MarkerShape::triangle_up ? 1.0 : -1.0;
      cairo_move_to(cr, x, y - s * 1.1 * r);
      cairo_line_to(cr, x + r, y + s * 0.7 * r);
      cairo_line_to(cr, x - r, y + s * 0.7 * r);
      cairo_close_path(cr);
      break;
    }
    case MarkerShape::diamond:
      cairo_move_to(cr, x, y - 1.15 * r);
      cairo_line_to(cr, x + 0.9 * r, y);
      cairo_line_to(cr, x, y + 1.15 * r);
      cairo_line_to(cr, x - 0.9 * r, y);
      cairo_close_path(cr);
      break;
    case MarkerShape::cross:
      segment(cr, x - r, y - r, x + r, y + r);
      segment(cr, x - r, y + r, x + r, y - r);
      break;
    case MarkerShape::plus:
      segment(cr, x - r, y, x + r, y);
      segment(cr, x, y - r, x, y + r);
      break;
  }
  cairo_set_dash(cr, nullptr, 0, 0.0);
  const bool stroke_only =
      !style.filled || style.shape == MarkerShape::cross || style.shape == MarkerShape::plus;
  if (stroke_only) {
    set_color(cr, style.color);
    cairo_set_line_width(cr, 1.2);
    cairo_stroke(cr);
  } else {
    set_color(cr, style.color);
    cairo_fill_preserve(cr);
    set_color(cr, {0.0, 0.0, 0.0, 0.6 * style.color.a});  // thin dark rim keeps overlaps legible
    cairo_set_line_width(cr, 0.5);
    cairo_stroke(cr);
  }
}

// ---- The renderer ---------------------------------------------------------------------------

class Renderer {
 public:
  Renderer(const Figure& figure, cairo_t* cr)
      : figure_(figure),
        cr_(cr),
        x_(figure.x_axis(), data_range(figure.items(), true, figure.x_axis().scale)),
        y_(figure.y_axis(), data_range(figure.items(), false, figure.y_axis().scale)) {}

  void draw() {
    cairo_select_font_face(cr_, kFontFamily, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    set_color(cr_, {1.0, 1.0, 1.0, 1.0});
    cairo_paint(cr_);
    layout();
    draw_grid();
    {
      const canvas::Clip clip(cr_, left_, top_, right_ - left_, bottom_ - top_);
      // Shaded regions under lines under markers: order by kind, then by call order.
      for (int pass = 0; pass < 4; ++pass) {
        for (const Figure::Item& item : figure_.items()) draw_item(item, pass);
      }
    }
    for (const Figure::Item& item : figure_.items()) draw_item(item, 4);
    draw_axes();
    draw_legend();
  }

 private:
  double px(double x) const { return left_ + x_.fraction(x) * (right_ - left_); }
  double py(double y) const { return bottom_ - y_.fraction(y) * (bottom_ - top_); }

  void layout() {
    double widest = 0.0;
    for (const Tick& tick : y_.ticks())
      widest = std::max(widest, text_width(cr_, tick.label, kTickFontPt));
    left_ = 12.0 + kLabelFontPt * 1.4 + widest + 8.0;
    right_ = figure_.width_pt() - 16.0;
    if (figure_.legend_position() == LegendPosition::outside_right && !figure_.legend().empty())
      right_ -= legend_size().first + 8.0;
    top_ = figure_.title().empty() ? 14.0 : 14.0 + kTitleFontPt * 1.6;
    bottom_ = figure_.height_pt() - (12.0 + kLabelFontPt * 1.4 + kTickFontPt * 1.8);
    if (right_ - left_ < 40.0 || bottom_ - top_ < 40.0) {
      throw std::invalid_argument("figure of " + std::to_string(figure_.width_pt()) + " × " +
                                  std::to_string(figure_.height_pt()) +
                                  " pt is too small for its labels; make it larger");
    }
  }

  void draw_grid() {
    cairo_set_line_width(cr_, 0.5);
    set_color(cr_, kGrid);
    cairo_set_dash(cr_, nullptr, 0, 0.0);
    for (const Tick& tick : x_.ticks()) {
      if (tick.label.empty()) continue;
      segment(cr_, px(tick.value), top_, px(tick.value), bottom_);
    }
    for (const Tick& tick : y_.ticks()) {
      if (tick.label.empty()) continue;
      segment(cr_, left_, py(tick.value), right_, py(tick.value));
    }
    cairo_stroke(cr_);
  }

  // pass 0: vertical bands and bands; 1: error bars; 2: lines; 3: markers and data text;
  // 4 (unclipped): bottom markers and axes-fraction text.
  void draw_item(const Figure::Item& item, int pass) {
    std::visit(
        [&](const auto& it) {
          using T = std::decay_t<decltype(it)>;
          if constexpr (std::is_same_v<T, Figure::VerticalBand>) {
            if (pass == 0) draw_vertical_band(it);
          } else if constexpr (std::is_same_v<T, Figure::Band>) {
            if (pass == 0) draw_band(it);
          } else if constexpr (std::is_same_v<T, Figure::ErrorBars>) {
            if (pass == 1) draw_error_bars(it);
          } else if constexpr (std::is_same_v<T, Figure::Line>) {
            if (pass == 2) draw_line(it);
          } else if constexpr (std::is_same_v<T, Figure::VerticalLine>) {
            if (pass == 2) draw_vertical_line(it);
          } else if constexpr (std::is_same_v<T, Figure::Points>) {
            if (pass == 3) draw_points(it);
          } else if constexpr (std::is_same_v<T, Figure::BottomMarkers>) {
            if (pass == 4) draw_bottom_markers(it);
          } else if constexpr (std::is_same_v<T, Figure::Text>) {
            if (pass == (it.in_axes ? 4 : 3)) draw_text_item(it);
          }
        },
        item);
  }

  void draw_vertical_band(const Figure::VerticalBand& band) {
    if (!x_.drawable(band.x_low) || !x_.drawable(band.x_high)) return;
    set_color(cr_, band.fill);
    cairo_rectangle(cr_, px(band.x_low), top_, px(band.x_high) - px(band.x_low), bottom_ - top_);
    cairo_fill(cr_);
  }

  void draw_band(const Figure::Band& band) {
    std::vector<std::size_t> ok;
    for (std::size_t i = 0; i < band.x.size(); ++i) {
      if (x_.drawable(band.x[i]) && y_.drawable(band.y_low[i]) && y_.drawable(band.y_high[i])) {
        ok.push_back(i);
      }
    }
    if (ok.size() < 2) return;
    cairo_new_path(cr_);
    for (std::size_t i : ok) cairo_line_to(cr_, px(band.x[i]), py(band.y_high[i]));
    for (auto it = ok.rbegin(); it != ok.rend(); ++it) {
      cairo_line_to(cr_, px(band.x[*it]), py(band.y_low[*it]));
    }
    cairo_close_path(cr_);
    set_color(cr_, band.fill);
    cairo_fill(cr_);
  }

  void draw_error_bars(const Figure::ErrorBars& bars) {
    set_color(cr_, bars.color);
    cairo_set_line_width(cr_, bars.width_pt);
    cairo_set_dash(cr_, nullptr, 0, 0.0);
    const double cap = 2.0;
    for (std::size_t i = 0; i < bars.x.size(); ++i) {
      if (!x_.drawable(bars.x[i]) || !y_.drawable(bars.y_low[i]) || !y_.drawable(bars.y_high[i])) {
        continue;
      }
      const double x = px(bars.x[i]), lo = py(bars.y_low[i]), hi = py(bars.y_high[i]);
      segment(cr_, x, lo, x, hi);
      segment(cr_, x - cap, lo, x + cap, lo);
      segment(cr_, x - cap, hi, x + cap, hi);
    }
    cairo_stroke(cr_);
  }

  void draw_line(const Figure::Line& line) {
    apply_line_style(cr_, line.style);
    cairo_new_path(cr_);
    bool pen_down = false;
    for (std::size_t i = 0; i < line.x.size(); ++i) {
      if (!x_.drawable(line.x[i]) || !y_.drawable(line.y[i])) {
        pen_down = false;  // a gap, not a jump across missing values
        continue;
      }
      (pen_down ? cairo_line_to : cairo_move_to)(cr_, px(line.x[i]), py(line.y[i]));
      pen_down = true;
    }
    cairo_stroke(cr_);
  }

  void draw_vertical_line(const Figure::VerticalLine& line) {
    if (!x_.drawable(line.x)) return;
    apply_line_style(cr_, line.style);
    segment(cr_, px(line.x), top_, px(line.x), bottom_);
    cairo_stroke(cr_);
  }

  void draw_points(const Figure::Points& points) {
    for (std::size_t i = 0; i < points.x.size(); ++i) {
      if (x_.drawable(points.x[i]) && y_.drawable(points.y[i])) {
        draw_marker(cr_, px(points.x[i]), py(points.y[i]), points.style);
      }
    }
  }

  void draw_bottom_markers(const Figure::BottomMarkers& markers) {
    const double y = bottom_ - 0.5 * markers.style.size_pt - 2.0;
    for (double x : markers.x) {
      if (x_.drawable(x) && x >= x_.min() && x <= x_.max())
        draw_marker(cr_, px(x), y, markers.style);
    }
  }

  void draw_text_item(const Figure::Text& text) {
    double x = 0.0, y = 0.0;
    if (text.in_axes) {
      x = left_ + text.x * (right_ - left_);
      y = bottom_ - text.y * (bottom_ - top_);
    } else {
      if (!x_.drawable(text.x) || !y_.drawable(text.y)) return;
      x = px(text.x);
      y = py(text.y);
    }
    if (text.style.boxed) {
      // A light backing keeps annotations readable where they cross data or bands.
      const double width = text_width(cr_, text.text, text.style.size_pt);
      const double x0 = text.style.anchor == TextAnchor::left     ? x
                        : text.style.anchor == TextAnchor::centre ? x - 0.5 * width
                                                                  : x - width;
      cairo_rectangle(cr_, x0 - 2.0, y - 0.95 * text.style.size_pt, width + 4.0,
                      1.35 * text.style.size_pt);
      set_color(cr_, {1.0, 1.0, 1.0, 0.8});
      cairo_fill(cr_);
    }
    draw_text(cr_, x, y, text.text, text.style);
  }

  void draw_axes() {
    cairo_set_dash(cr_, nullptr, 0, 0.0);
    set_color(cr_, kBlack);
    cairo_set_line_width(cr_, 0.8);
    cairo_rectangle(cr_, left_, top_, right_ - left_, bottom_ - top_);
    cairo_stroke(cr_);
    const TextStyle tick_centre{kTickFontPt, kBlack, TextAnchor::centre};
    const TextStyle tick_right{kTickFontPt, kBlack, TextAnchor::right};
    for (const Tick& tick : x_.ticks()) {
      const double x = px(tick.value), length = tick.label.empty() ? 2.5 : 5.0;
      segment(cr_, x, bottom_, x, bottom_ - length);
      segment(cr_, x, top_, x, top_ + length);
      cairo_stroke(cr_);
      if (!tick.label.empty())
        draw_text(cr_, x, bottom_ + 4.0 + kTickFontPt * 1.1, tick.label, tick_centre);
    }
    for (const Tick& tick : y_.ticks()) {
      const double y = py(tick.value), length = tick.label.empty() ? 2.5 : 5.0;
      segment(cr_, left_, y, left_ + length, y);
      segment(cr_, right_, y, right_ - length, y);
      cairo_stroke(cr_);
      if (!tick.label.empty())
        draw_text(cr_, left_ - 4.0, y + 0.35 * kTickFontPt, tick.label, tick_right);
    }
    const TextStyle label{kLabelFontPt, kBlack, TextAnchor::centre};
    draw_text(cr_, 0.5 * (left_ + right_), figure_.height_pt() - 10.0, figure_.x_axis().label,
              label);
    canvas::turned_up(cr_, 8.0 + kLabelFontPt, 0.5 * (top_ + bottom_),
                      [&] { draw_text(cr_, 0.0, 0.0, figure_.y_axis().label, label); });
    if (!figure_.title().empty()) {
      // A long title (a study's name and protocol) shrinks to the figure's width, and is centred
      // over the axes where it fits, else as near to that as the figure's edges let it be.
      constexpr double kEdge = 8.0;
      const double room = figure_.width_pt() - 2.0 * kEdge;
      double size = kTitleFontPt;
      const double full = text_width(cr_, figure_.title(), size);
      if (full > room) size = std::max(6.0, size * room / full);
      const double half = 0.5 * text_width(cr_, figure_.title(), size);
      const double x = std::clamp(0.5 * (left_ + right_), kEdge + half, std::max(kEdge + half, figure_.width_pt() - kEdge - half));
      draw_text(cr_, x, 10.0 + kTitleFontPt, figure_.title(), {size, kBlack, TextAnchor::centre});
    }
  }

  // Width and height of the legend box [pt].
  std::pair<double, double> legend_size() const {
    const auto& entries = figure_.legend();
    const double row = kLegendFontPt * 1.6, sample = 22.0, pad = 6.0;
    double widest = 0.0;
    for (const auto& entry : entries)
      widest = std::max(widest, text_width(cr_, entry.label, kLegendFontPt));
    return {pad + sample + 6.0 + widest + pad,
            pad + row * static_cast<double>(entries.size()) + pad - 0.4 * row};
  }

  void draw_legend() {
    const auto& entries = figure_.legend();
    if (entries.empty() || figure_.legend_position() == LegendPosition::none) return;
    const double row = kLegendFontPt * 1.6, sample = 22.0, pad = 6.0;
    const auto [width, height] = legend_size();
    const LegendPosition position = figure_.legend_position();
    const bool at_left =
        position == LegendPosition::upper_left || position == LegendPosition::lower_left;
    const bool at_top = position == LegendPosition::upper_left ||
                        position == LegendPosition::upper_right ||
                        position == LegendPosition::outside_right;
    const double x0 = position == LegendPosition::outside_right ? right_ + 8.0
                      : at_left                                  ? left_ + 8.0
                                                                 : right_ - 8.0 - width;
    const double y0 = at_top ? top_ + (position == LegendPosition::outside_right ? 0.0 : 8.0)
                             : bottom_ - 8.0 - height;
    cairo_set_dash(cr_, nullptr, 0, 0.0);
    cairo_rectangle(cr_, x0, y0, width, height);
    set_color(cr_, {1.0, 1.0, 1.0, 0.85});
    cairo_fill_preserve(cr_);
    set_color(cr_, {0.6, 0.6, 0.6, 1.0});
    cairo_set_line_width(cr_, 0.5);
    cairo_stroke(cr_);
    for (std::size_t k = 0; k < entries.size(); ++k) {
      const double centre_y = y0 + pad + row * (static_cast<double>(k) + 0.3);
      const double sx = x0 + pad;
      draw_legend_sample(figure_.items()[entries[k].item], sx, sx + sample, centre_y);
      draw_text(cr_, sx + sample + 6.0, centre_y + 0.35 * kLegendFontPt, entries[k].label,
                {kLegendFontPt, kBlack, TextAnchor::left});
    }
  }

  void draw_legend_sample(const Figure::Item& item, double x0, double x1, double y) {
    const double xm = 0.5 * (x0 + x1);
    std::visit(
        [&](const auto& it) {
          using T = std::decay_t<decltype(it)>;
          if constexpr (std::is_same_v<T, Figure::Points> ||
                        std::is_same_v<T, Figure::BottomMarkers>) {
            draw_marker(cr_, xm, y, it.style);
          } else if constexpr (std::is_same_v<T, Figure::Line> ||
                               std::is_same_v<T, Figure::VerticalLine>) {
            apply_line_style(cr_, it.style);
            segment(cr_, x0, y, x1, y);
            cairo_stroke(cr_);
          } else if constexpr (std::is_same_v<T, Figure::Band> ||
                               std::is_same_v<T, Figure::VerticalBand>) {
            set_color(cr_, it.fill);
            cairo_rectangle(cr_, x0, y - 4.0, x1 - x0, 8.0);
            cairo_fill(cr_);
          } else if constexpr (std::is_same_v<T, Figure::ErrorBars>) {
            set_color(cr_, it.color);
            segment(cr_, xm, y - 5.0, xm, y + 5.0);
            cairo_stroke(cr_);
          }
        },
        item);
  }

  const Figure& figure_;
  cairo_t* cr_;
  AxisMap x_, y_;
  double left_ = 0.0, right_ = 0.0, top_ = 0.0, bottom_ = 0.0;
};

void render(const Figure& figure, cairo_surface_t* surface, double scale) {
  const canvas::ContextPtr cr = canvas::context(surface, "figure");
  cairo_scale(cr.get(), scale, scale);
  Renderer(figure, cr.get()).draw();
  canvas::check(cr.get(), "figure");
}

cairo_status_t append_to_string(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

std::string xml_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

void check_sizes(std::size_t x, std::size_t y, const char* what) {
  if (x != y) {
    throw std::invalid_argument(std::string("figure: ") + what + " has " + std::to_string(x) +
                                " x values but " + std::to_string(y) + " y values");
  }
}

}  // namespace

std::string escape_markup(const std::string& text) {
  std::string out;
  for (char ch : text) {
    if (ch == '_' || ch == '^' || ch == '\\') out += '\\';
    out += ch;
  }
  return out;
}

Color palette_color(std::size_t index) {
  static constexpr Color kOkabeIto[] = {
      {0.000, 0.447, 0.698, 1.0},  // blue
      {0.835, 0.369, 0.000, 1.0},  // vermillion
      {0.000, 0.620, 0.451, 1.0},  // bluish green
      {0.800, 0.475, 0.655, 1.0},  // reddish purple
      {0.902, 0.624, 0.000, 1.0},  // orange
      {0.337, 0.706, 0.914, 1.0},  // sky blue
      {0.941, 0.894, 0.259, 1.0},  // yellow
      {0.000, 0.000, 0.000, 1.0},  // black
  };
  return kOkabeIto[index % std::size(kOkabeIto)];
}

MarkerShape palette_marker(std::size_t index) {
  static constexpr MarkerShape kShapes[] = {MarkerShape::circle, MarkerShape::square,
                                            MarkerShape::triangle_up, MarkerShape::diamond,
                                            MarkerShape::triangle_down};
  return kShapes[index % std::size(kShapes)];
}

Figure::Figure(double width_pt, double height_pt) : width_pt_(width_pt), height_pt_(height_pt) {
  if (!(width_pt > 0.0 && height_pt > 0.0 && std::isfinite(width_pt) && std::isfinite(height_pt))) {
    throw std::invalid_argument("figure size must be positive and finite, got " +
                                std::to_string(width_pt) + " × " + std::to_string(height_pt) +
                                " pt");
  }
}

void Figure::set_x_axis(std::string label, AxisScale scale, std::optional<double> min,
                        std::optional<double> max) {
  x_axis_ = {std::move(label), scale, min, max};
}

void Figure::set_y_axis(std::string label, AxisScale scale, std::optional<double> min,
                        std::optional<double> max) {
  y_axis_ = {std::move(label), scale, min, max};
}

void Figure::add(Item item, std::string legend) {
  items_.push_back(std::move(item));
  if (!legend.empty()) legend_.push_back({std::move(legend), items_.size() - 1});
}

void Figure::add_points(std::vector<double> x, std::vector<double> y, MarkerStyle style,
                        std::string legend) {
  check_sizes(x.size(), y.size(), "a point series");
  add(Points{std::move(x), std::move(y), style}, std::move(legend));
}

void Figure::add_bottom_markers(std::vector<double> x, MarkerStyle style, std::string legend) {
  add(BottomMarkers{std::move(x), style}, std::move(legend));
}

void Figure::add_error_bars(std::vector<double> x, std::vector<double> y_low,
                            std::vector<double> y_high, Color color, double width_pt) {
  check_sizes(x.size(), y_low.size(), "an error-bar series (low ends)");
  check_sizes(x.size(), y_high.size(), "an error-bar series (high ends)");
  add(ErrorBars{std::move(x), std::move(y_low), std::move(y_high), color, width_pt}, {});
}

void Figure::add_line(std::vector<double> x, std::vector<double> y, LineStyle style,
                      std::string legend) {
  check_sizes(x.size(), y.size(), "a line");
  add(Line{std::move(x), std::move(y), std::move(style)}, std::move(legend));
}

void Figure::add_band(std::vector<double> x, std::vector<double> y_low, std::vector<double> y_high,
                      Color fill, std::string legend) {
  check_sizes(x.size(), y_low.size(), "a band (lower edge)");
  check_sizes(x.size(), y_high.size(), "a band (upper edge)");
  add(Band{std::move(x), std::move(y_low), std::move(y_high), fill}, std::move(legend));
}

void Figure::add_vertical_band(double x_low, double x_high, Color fill, std::string legend) {
  add(VerticalBand{std::min(x_low, x_high), std::max(x_low, x_high), fill}, std::move(legend));
}

void Figure::add_vertical_line(double x, LineStyle style, std::string legend) {
  add(VerticalLine{x, std::move(style)}, std::move(legend));
}

void Figure::add_text(double x, double y, std::string text, TextStyle style) {
  add(Text{x, y, false, std::move(text), style}, {});
}

void Figure::add_text_in_axes(double fx, double fy, std::string text, TextStyle style) {
  add(Text{fx, fy, true, std::move(text), style}, {});
}

void Figure::write_png(const std::string& path, double pixels_per_pt) const {
  const int width = static_cast<int>(std::ceil(width_pt_ * pixels_per_pt));
  const int height = static_cast<int>(std::ceil(height_pt_ * pixels_per_pt));
  const canvas::SurfacePtr surface = canvas::image(width, height, "figure");
  render(*this, surface.get(), pixels_per_pt);
  canvas::write_png(surface.get(), path, "figure");
}

std::string Figure::svg() const {
  std::string document;
  {
    const canvas::SurfacePtr surface(
        cairo_svg_surface_create_for_stream(append_to_string, &document, width_pt_, height_pt_));
    render(*this, surface.get(), 1.0);
    cairo_surface_finish(surface.get());
    if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS) {
      throw std::runtime_error(std::string("figure: SVG output failed: ") +
                               cairo_status_to_string(cairo_surface_status(surface.get())));
    }
  }
  // cairo numbers its surfaces with a process-wide counter ("surface5"): rename it so that the
  // same figure gives the same bytes however many figures were drawn before.
  document = std::regex_replace(document, std::regex("surface[0-9]+"), "figure");
  std::string description;
  for (const Item& item : items_) {
    if (const auto* text = std::get_if<Text>(&item)) description += text->text + "\n";
  }
  description += "x: " + x_axis_.label + "\ny: " + y_axis_.label + "\n";
  for (const LegendEntry& entry : legend_) description += "legend: " + entry.label + "\n";
  const std::string metadata =
      "<title>" + xml_escape(title_) + "</title>\n<desc>" + xml_escape(description) + "</desc>\n";
  const std::size_t svg_open = document.find("<svg");
  const std::size_t svg_open_end =
      svg_open == std::string::npos ? svg_open : document.find('>', svg_open);
  if (svg_open_end != std::string::npos) document.insert(svg_open_end + 1, "\n" + metadata);
  return document;
}

void Figure::write_svg(const std::string& path) const {
  const std::string document = svg();
  AtomicFile file(path);
  std::ofstream out(file.temp_path(), std::ios::binary);
  out << document;
  out.close();
  if (!out) {
    throw std::runtime_error("figure: cannot write SVG '" + path +
                             "' — check that the folder exists and is writable");
  }
  file.commit();
}

}  // namespace crevasse::analysis
