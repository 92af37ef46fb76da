#include "analysis/cairo_canvas.hpp"

#include <stdexcept>

#include "engine/atomic_file.hpp"

namespace crevasse::analysis::canvas {

SurfacePtr image(int width_px, int height_px, const std::string& who) {
  SurfacePtr surface(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width_px, height_px));
  if (cairo_surface_status(surface.get()) != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error(who + ": cairo could not create a " + std::to_string(width_px) + " × " +
                             std::to_string(height_px) + " px image (out of memory?)");
  }
  return surface;
}

ContextPtr context(cairo_surface_t* surface, const std::string& who) {
  ContextPtr cr(cairo_create(surface));
  if (cairo_status(cr.get()) != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error(who + ": cairo could not start drawing: " +
                             cairo_status_to_string(cairo_status(cr.get())));
  }
  return cr;
}

void check(cairo_t* cr, const std::string& who) {
  if (cairo_status(cr) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(who + ": drawing failed: " + cairo_status_to_string(cairo_status(cr)));
}

void write_png(cairo_surface_t* surface, const std::string& path, const std::string& who) {
  AtomicFile file(path);
  const cairo_status_t status = cairo_surface_write_to_png(surface, file.temp_path().c_str());
  if (status != CAIRO_STATUS_SUCCESS) {
    throw std::runtime_error(who + ": cannot write PNG '" + path + "': " + cairo_status_to_string(status) +
                             " — check that the folder exists and is writable");
  }
  file.commit();
}

void set_color(cairo_t* cr, const Color& c) { cairo_set_source_rgba(cr, c.r, c.g, c.b, c.a); }

void segment(cairo_t* cr, double x0, double y0, double x1, double y1) {
  cairo_move_to(cr, x0, y0);
  cairo_line_to(cr, x1, y1);
}

void show_text(cairo_t* cr, double x, double y, const std::string& text, double align_x, double align_y) {
  cairo_text_extents_t e;
  cairo_text_extents(cr, text.c_str(), &e);
  cairo_move_to(cr, x - e.x_bearing - align_x * e.width, y - e.y_bearing - align_y * e.height);
  cairo_show_text(cr, text.c_str());
}

Clip::Clip(cairo_t* cr, double x, double y, double width, double height) : cr_(cr) {
  cairo_save(cr);
  cairo_rectangle(cr, x, y, width, height);
  cairo_clip(cr);
}

Clip::~Clip() { cairo_restore(cr_); }

}  // namespace crevasse::analysis::canvas
