#pragma once
// The cairo plumbing the figures (plot.cpp) and the side views (side_view.cpp) share: owned
// surfaces and contexts, status checks, PNG output, and a few drawing shorthands. `who` ("figure",
// "side view") starts every error message.
#include <cairo.h>

#include <memory>
#include <numbers>
#include <string>

#include "analysis/plot.hpp"

namespace crevasse::analysis::canvas {

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* cr) const { cairo_destroy(cr); }
};
using SurfacePtr = std::unique_ptr<cairo_surface_t, SurfaceDeleter>;
using ContextPtr = std::unique_ptr<cairo_t, ContextDeleter>;

// An ARGB image, and a context to draw on a surface; both throw when cairo cannot make them.
SurfacePtr image(int width_px, int height_px, const std::string& who);
ContextPtr context(cairo_surface_t* surface, const std::string& who);

// Throws when drawing on cr failed (cairo stops drawing at the first error and says so only here).
void check(cairo_t* cr, const std::string& who);

// The surface as a PNG file at path, whole or not at all.
void write_png(cairo_surface_t* surface, const std::string& path, const std::string& who);

void set_color(cairo_t* cr, const Color& c);

// A straight line added to the current path (stroked by the caller, alone or with others).
void segment(cairo_t* cr, double x0, double y0, double x1, double y1);

// Plain text placed by its ink box: align 0 puts the box's left (top) edge at x (y), 0.5 its
// centre, 1 its right (bottom) edge.
void show_text(cairo_t* cr, double x, double y, const std::string& text, double align_x, double align_y);

// Draws inside the rectangle only, until the object goes out of scope.
class Clip {
 public:
  Clip(cairo_t* cr, double x, double y, double width, double height);
  ~Clip();
  Clip(const Clip&) = delete;
  Clip& operator=(const Clip&) = delete;

 private:
  cairo_t* cr_;
};

// Runs draw() with the origin at (x, y) and the axes turned a quarter turn anticlockwise, for a
// vertical axis label.
template <class Draw>
void turned_up(cairo_t* cr, double x, double y, Draw draw) {
  cairo_save(cr);
  cairo_translate(cr, x, y);
  cairo_rotate(cr, -0.5 * std::numbers::pi);
  draw();
  cairo_restore(cr);
}

}  // namespace crevasse::analysis::canvas
