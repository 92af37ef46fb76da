#pragma once
// A to-scale side view of the glacier as a PNG: bed in grey, ice coloured by damage
// (light blue intact → near-black broken, "darker = more damage"), optional marks on the
// measured crevasses, a title line and metre axes.
#include <filesystem>
#include <optional>
#include <string>

#include "analysis/crevasse_measure.hpp"
#include "engine/snapshot.hpp"

namespace crevasse::analysis {

struct SideViewOptions {
  int width_px = 1600;  // image width; the height follows from equal x and z scales
  // x-range shown; default the whole ice plus a margin of 0.25·H_i.
  std::optional<double> x_min_m;
  std::optional<double> x_max_m;
  // Appended to the automatic title line "t = … s   H_i = … m" (e.g. "Π = 0.05").
  std::string title_extra;
  bool show_title = true;
  // Damage colour scale: the same criterion as the measurement, so the colour at the damage
  // threshold is the same whether or not the run had softening.
  double damage_threshold = 0.95;
  double eps_v_p_threshold = 0.01;
  // 3D: draw only |y − y_c| ≤ width/2 (y_c the middle of the y-range). Absent: every particle,
  // each pixel showing the most damaged particle behind it, so a crevasse anywhere across the
  // width is visible.
  std::optional<double> y_band_width_m;
};

struct SideViewImageSize {
  int width_px = 0;
  int height_px = 0;
};

// Writes the PNG; when `marks` is given, each of its crevasses gets a numbered tick at its
// surface position and a line down to its depth. Throws std::invalid_argument for an empty
// snapshot or an empty x-range, std::runtime_error when the file cannot be written.
SideViewImageSize write_side_view_png(const ParticleSnapshot& snapshot,
                                      const std::filesystem::path& path,
                                      const SideViewOptions& options = {},
                                      const CrevasseMeasurement* marks = nullptr);

}  // namespace crevasse::analysis
