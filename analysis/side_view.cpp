#include "analysis/side_view.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "analysis/cairo_canvas.hpp"
#include "analysis/damage_criterion.hpp"

namespace crevasse::analysis {

namespace {

using canvas::segment;
using canvas::set_color;
using canvas::show_text;

struct Rgb {
  double r, g, b;
};

// Light blue for intact ice through mid blue to near-black at full damage; the last stop sits
// at the damage threshold's level so "damaged" reads as dark at a glance.
Rgb damage_colour(double level) {
  struct Stop {
    double at;
    Rgb c;
  };
  static constexpr std::array<Stop, 5> stops = {{{0.0, {0.84, 0.92, 0.98}},
                                                 {0.5, {0.56, 0.72, 0.88}},
                                                 {0.8, {0.27, 0.42, 0.66}},
                                                 {0.95, {0.09, 0.13, 0.28}},
                                                 {1.0, {0.02, 0.03, 0.08}}}};
  level = std::clamp(level, 0.0, 1.0);
  for (std::size_t i = 1; i < stops.size(); ++i) {
    if (level <= stops[i].at) {
      const double t = (level - stops[i - 1].at) / (stops[i].at - stops[i - 1].at);
      const Rgb& a = stops[i - 1].c;
      const Rgb& b = stops[i].c;
      return {a.r + t * (b.r - a.r), a.g + t * (b.g - a.g), a.b + t * (b.b - a.b)};
    }
  }
  return stops.back().c;
}

std::uint32_t argb(Rgb c) {
  auto byte = [](double v) {
    return static_cast<std::uint32_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
  };
  return 0xff000000u | (byte(c.r) << 16) | (byte(c.g) << 8) | byte(c.b);
}

// 1, 2 or 5 × 10^k, the smallest such step giving ticks at least `min_step` apart.
double nice_step(double min_step) {
  const double p = std::pow(10.0, std::floor(std::log10(min_step)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= min_step) return m * p;
  }
  return 10.0 * p;
}

std::string format_metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f", std::abs(v) < 0.5 ? 0.0 : v);
  return buf;
}

// Maps metres to pixels with one scale for x and z (true aspect ratio).
struct Frame {
  double x0_m, z1_m, scale_px_per_m;
  double left_px, top_px, width_px, height_px;
  double px(double x_m) const { return left_px + (x_m - x0_m) * scale_px_per_m; }
  double py(double z_m) const { return top_px + (z1_m - z_m) * scale_px_per_m; }
};

void draw_bed(cairo_t* cr, const Frame& f, const ParticleSnapshot& s) {
  if (s.bed_profile.size() < 2) return;
  const double bottom = f.top_px + f.height_px;
  cairo_move_to(cr, f.px(s.bed_profile.front()[0]), bottom);
  for (const auto& v : s.bed_profile) cairo_line_to(cr, f.px(v[0]), f.py(v[1]));
  cairo_line_to(cr, f.px(s.bed_profile.back()[0]), bottom);
  cairo_close_path(cr);
  set_color(cr, {0.62, 0.62, 0.62});
  cairo_fill(cr);
}

void draw_bed_outline(cairo_t* cr, const Frame& f, const ParticleSnapshot& s) {
  if (s.bed_profile.size() < 2) return;
  cairo_move_to(cr, f.px(s.bed_profile.front()[0]), f.py(s.bed_profile.front()[1]));
  for (const auto& v : s.bed_profile) cairo_line_to(cr, f.px(v[0]), f.py(v[1]));
  set_color(cr, {0.30, 0.30, 0.30});
  cairo_set_line_width(cr, 1.5);
  cairo_stroke(cr);
}

// Each particle covers a square 1.3 spacings wide (at least one pixel): the overlap closes the
// pin-holes that jittered particles would leave, while a real opening (wider than ~1.5
// spacings) stays visible. A pixel shows the most damaged particle on it, so a
// one-particle-wide crack is never painted over by intact ice.
void paint_particles(cairo_surface_t* surface, const Frame& f, const ParticleSnapshot& s,
                     const DamageCriterion& criterion, const SideViewOptions& o, double y_centre) {
  const int w = cairo_image_surface_get_width(surface);
  const int h = cairo_image_surface_get_height(surface);
  const int stride = cairo_image_surface_get_stride(surface) / 4;
  auto* pixels = reinterpret_cast<std::uint32_t*>(cairo_image_surface_get_data(surface));
  std::vector<float> level(static_cast<std::size_t>(w) * h, -1.0f);
  const double spacing = s.particle_spacing_m > 0.0 ? s.particle_spacing_m : 0.5 * s.dx_m;
  const double half_px = std::max(0.5, 0.65 * spacing * f.scale_px_per_m);
  const int x_lo = static_cast<int>(f.left_px), x_hi = static_cast<int>(f.left_px + f.width_px);
  const int y_lo = static_cast<int>(f.top_px), y_hi = static_cast<int>(f.top_px + f.height_px);
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.dim == 3 && o.y_band_width_m && std::abs(s.y[i] - y_centre) > 0.5 * *o.y_band_width_m) {
      continue;
    }
    const double cx = f.px(s.x[i]), cy = f.py(s.z[i]);
    if (!std::isfinite(cx) || !std::isfinite(cy)) continue;
    const int i0 = std::max(x_lo, static_cast<int>(std::floor(cx - half_px + 0.5)));
    const int i1 = std::min(x_hi, static_cast<int>(std::floor(cx + half_px + 0.5)));
    const int j0 = std::max(y_lo, static_cast<int>(std::floor(cy - half_px + 0.5)));
    const int j1 = std::min(y_hi, static_cast<int>(std::floor(cy + half_px + 0.5)));
    const auto d = static_cast<float>(criterion.level(s.eps_v_p[i]));
    for (int j = j0; j < std::max(j1, j0 + 1) && j < y_hi; ++j) {
      for (int k = i0; k < std::max(i1, i0 + 1) && k < x_hi; ++k) {
        float& l = level[static_cast<std::size_t>(j) * w + k];
        l = std::max(l, d);
      }
    }
  }
  cairo_surface_flush(surface);
  for (int j = 0; j < h; ++j) {
    for (int k = 0; k < w; ++k) {
      const float l = level[static_cast<std::size_t>(j) * w + k];
      if (l >= 0.0f) pixels[static_cast<std::size_t>(j) * stride + k] = argb(damage_colour(l));
    }
  }
  cairo_surface_mark_dirty(surface);
}

void draw_axes(cairo_t* cr, const Frame& f) {
  set_color(cr, {0.15, 0.15, 0.15});
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, f.left_px + 0.5, f.top_px + 0.5, f.width_px - 1.0, f.height_px - 1.0);
  cairo_stroke(cr);
  cairo_set_font_size(cr, 12.0);
  const double bottom = f.top_px + f.height_px;
  const double x_step = nice_step(90.0 / f.scale_px_per_m);
  const double x1_m = f.x0_m + f.width_px / f.scale_px_per_m;
  for (double x = std::ceil(f.x0_m / x_step) * x_step; x <= x1_m + 1e-9; x += x_step) {
    const double p = std::round(f.px(x)) + 0.5;
    segment(cr, p, bottom, p, bottom + 5.0);
    cairo_stroke(cr);
    show_text(cr, p, bottom + 8.0, format_metres(x), 0.5, 0.0);
  }
  show_text(cr, f.left_px + 0.5 * f.width_px, bottom + 26.0, "x [m]", 0.5, 0.0);
  const double z_step = nice_step(40.0 / f.scale_px_per_m);
  const double z0_m = f.z1_m - f.height_px / f.scale_px_per_m;
  for (double z = std::ceil(z0_m / z_step) * z_step; z <= f.z1_m + 1e-9; z += z_step) {
    const double p = std::round(f.py(z)) + 0.5;
    segment(cr, f.left_px - 5.0, p, f.left_px, p);
    cairo_stroke(cr);
    show_text(cr, f.left_px - 8.0, p, format_metres(z), 1.0, 0.5);
  }
  canvas::turned_up(cr, 14.0, f.top_px + 0.5 * f.height_px,
                    [&] { show_text(cr, 0.0, 0.0, "z [m]", 0.5, 0.5); });
}

void draw_marks(cairo_t* cr, const Frame& f, const CrevasseMeasurement& m) {
  // The measurement window: two grey dashed verticals over the whole height.
  set_color(cr, {0.45, 0.45, 0.45});
  cairo_set_line_width(cr, 1.0);
  const double window_dash[] = {6.0, 4.0};
  cairo_set_dash(cr, window_dash, 2, 0.0);
  for (double x : {m.settings.window_min_x_m, m.settings.window_max_x_m}) {
    const double p = std::round(f.px(x)) + 0.5;
    if (p < f.left_px || p > f.left_px + f.width_px) continue;
    segment(cr, p, f.top_px, p, f.top_px + f.height_px);
    cairo_stroke(cr);
  }
  cairo_set_dash(cr, nullptr, 0, 0.0);
  if (m.crevasses.empty()) return;
  double min_gap_px = 1e9;
  for (std::size_t i = 1; i < m.crevasses.size(); ++i) {
    min_gap_px =
        std::min(min_gap_px, (m.crevasses[i].x_m - m.crevasses[i - 1].x_m) * f.scale_px_per_m);
  }
  // Label every k-th crevasse so that numbers never overlap.
  const auto label_every = static_cast<std::size_t>(std::max(1.0, std::ceil(22.0 / min_gap_px)));
  cairo_set_font_size(cr, 10.0);
  for (std::size_t i = 0; i < m.crevasses.size(); ++i) {
    const Crevasse& c = m.crevasses[i];
    const double p = std::round(f.px(c.x_m)) + 0.5;
    const double top = f.py(c.surface_z_m);
    set_color(cr, {1.0, 0.42, 0.05});
    cairo_set_line_width(cr, 1.5);
    segment(cr, p, top - 12.0, p, top - 3.0);
    cairo_stroke(cr);
    cairo_set_line_width(cr, 1.0);
    const double dash[] = {3.0, 2.0};
    cairo_set_dash(cr, dash, 2, 0.0);
    segment(cr, p, top, p, f.py(c.surface_z_m - c.depth_m));
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0.0);
    segment(cr, p - 3.0, f.py(c.surface_z_m - c.depth_m), p + 3.0, f.py(c.surface_z_m - c.depth_m));
    cairo_stroke(cr);
    if (i % label_every == 0) {
      set_color(cr, {0.70, 0.15, 0.0});
      show_text(cr, p, top - 14.0, std::to_string(i + 1), 0.5, 1.0);
    }
  }
}

void draw_title_and_legend(cairo_t* cr, int width, const ParticleSnapshot& s,
                           const SideViewOptions& o, const CrevasseMeasurement* marks) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "t = %.1f s   H_i = %.0f m   dx = %.3g m", s.time_s,
                s.ice_thickness_m, s.dx_m);
  std::string title = buf;
  if (marks) {
    title += "   crevasses: " + std::to_string(marks->crevasses.size());
    if (marks->spacing_m) {
      std::snprintf(buf, sizeof buf, "   median spacing %.0f m", marks->spacing_m->median);
      title += buf;
    }
    if (marks->depth_m) {
      std::snprintf(buf, sizeof buf, "   median depth %.0f m", marks->depth_m->median);
      title += buf;
    }
  }
  if (!o.title_extra.empty()) title += "   " + o.title_extra;
  set_color(cr, {0.1, 0.1, 0.1});
  cairo_set_font_size(cr, 14.0);
  show_text(cr, 70.0, 12.0, title, 0.0, 0.0);

  // Colour bar: damage 0 … 1.
  const double bar_w = 160.0, bar_h = 10.0, bx = width - 20.0 - bar_w, by = 14.0;
  for (int k = 0; k < static_cast<int>(bar_w); ++k) {
    const Rgb c = damage_colour(k / (bar_w - 1.0));
    set_color(cr, {c.r, c.g, c.b});
    cairo_rectangle(cr, bx + k, by, 1.0, bar_h);
    cairo_fill(cr);
  }
  set_color(cr, {0.3, 0.3, 0.3});
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, bx + 0.5, by + 0.5, bar_w - 1.0, bar_h - 1.0);
  cairo_stroke(cr);
  set_color(cr, {0.1, 0.1, 0.1});
  cairo_set_font_size(cr, 11.0);
  show_text(cr, bx - 6.0, by + 0.5 * bar_h, "damage 0", 1.0, 0.5);
  show_text(cr, bx + bar_w + 4.0, by + 0.5 * bar_h, "1", 0.0, 0.5);
}

}  // namespace

SideViewImageSize write_side_view_png(const ParticleSnapshot& s, const std::filesystem::path& path,
                                      const SideViewOptions& o, const CrevasseMeasurement* marks) {
  if (s.size() == 0) throw std::invalid_argument("side view: the snapshot has no particles");
  if (s.z.size() != s.size() || s.eps_v_p.size() != s.size() ||
      (s.dim == 3 && s.y.size() != s.size())) {
    throw std::invalid_argument(
        "side view: snapshot arrays x, z, eps_v_p (and y in 3D) differ in length");
  }
  if (o.width_px < 200 || o.width_px > 16000) {
    throw std::invalid_argument("side view: width_px must lie in [200, 16000], got " +
                                std::to_string(o.width_px));
  }
  const DamageCriterion criterion =
      DamageCriterion::for_snapshot(s, o.damage_threshold, o.eps_v_p_threshold);

  double x_lo = 1e300, x_hi = -1e300, z_lo = 1e300, z_hi = -1e300, y_lo = 1e300, y_hi = -1e300;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (!std::isfinite(s.x[i]) || !std::isfinite(s.z[i])) continue;
    x_lo = std::min(x_lo, s.x[i]);
    x_hi = std::max(x_hi, s.x[i]);
    if (s.dim == 3) {
      y_lo = std::min(y_lo, s.y[i]);
      y_hi = std::max(y_hi, s.y[i]);
    }
  }
  const double h_i =
      s.ice_thickness_m > 0.0 ? s.ice_thickness_m : std::max(1.0, 0.05 * (x_hi - x_lo));
  const double x0 = o.x_min_m.value_or(x_lo - 0.25 * h_i);
  const double x1 = o.x_max_m.value_or(x_hi + 0.25 * h_i);
  if (!(x1 > x0)) {
    throw std::invalid_argument("side view: x-range [" + std::to_string(x0) + ", " +
                                std::to_string(x1) + "] m is empty; set x_min_m < x_max_m");
  }
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s.x[i] < x0 || s.x[i] > x1 || !std::isfinite(s.z[i])) continue;
    z_lo = std::min(z_lo, s.z[i]);
    z_hi = std::max(z_hi, s.z[i]);
  }
  for (const auto& v : s.bed_profile) {
    if (v[0] >= x0 && v[0] <= x1) z_lo = std::min(z_lo, v[1]);
  }
  if (z_lo > z_hi) {  // nothing inside the crop: show one ice thickness of bed
    z_lo = 0.0;
    z_hi = h_i;
  }
  // Rock below the lowest point, sky above the highest (room for the crevasse ticks).
  const double z0 = z_lo - 0.15 * h_i;

  constexpr double kLeft = 70.0, kRight = 20.0, kBottom = 46.0;
  const double top_margin = o.show_title ? 40.0 : 12.0;
  const double plot_w = o.width_px - kLeft - kRight;
  const double scale = plot_w / (x1 - x0);
  const double z1 = z_hi + 0.15 * h_i + 28.0 / scale;
  const double plot_h = (z1 - z0) * scale;
  const double height = std::ceil(plot_h + top_margin + kBottom);
  if (height > 16000.0) {
    throw std::invalid_argument("side view: at equal x/z scale the image would be " +
                                std::to_string(static_cast<long>(height)) +
                                " px tall; widen the x-range or reduce width_px");
  }
  const Frame frame{x0, z1, scale, kLeft, top_margin, plot_w, plot_h};

  const canvas::SurfacePtr surface = canvas::image(o.width_px, static_cast<int>(height), "side view");
  const canvas::ContextPtr cr = canvas::context(surface.get(), "side view");
  set_color(cr.get(), {1.0, 1.0, 1.0});
  cairo_paint(cr.get());
  {
    const canvas::Clip clip(cr.get(), frame.left_px, frame.top_px, frame.width_px, frame.height_px);
    draw_bed(cr.get(), frame, s);
  }
  paint_particles(surface.get(), frame, s, criterion, o, 0.5 * (y_lo + y_hi));
  {
    const canvas::Clip clip(cr.get(), frame.left_px, frame.top_px, frame.width_px, frame.height_px);
    draw_bed_outline(cr.get(), frame, s);
    if (marks) draw_marks(cr.get(), frame, *marks);
  }
  draw_axes(cr.get(), frame);
  if (o.show_title) draw_title_and_legend(cr.get(), o.width_px, s, o, marks);
  canvas::check(cr.get(), "side view");
  canvas::write_png(surface.get(), path.string(), "side view");
  return {o.width_px, static_cast<int>(height)};
}

}  // namespace crevasse::analysis
