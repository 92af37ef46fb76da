#include "engine/groups.hpp"
#include "study/case_views.hpp"

#include <cstdio>

#include "analysis/side_view.hpp"

namespace crevasse {

void write_case_views(const SceneConfig& scene, const ParticleSnapshot& final_snapshot,
                      const analysis::CrevasseMeasurement& m, const std::filesystem::path& dir,
                      const std::string& stem) {
  write_case_views(cohesion_ratio(scene.tensile_strength, scene.density, scene.gravity, scene.ice_thickness),
                   final_snapshot, m, dir, stem);
}

void write_case_views(double pi_group, const ParticleSnapshot& final_snapshot,
                      const analysis::CrevasseMeasurement& m, const std::filesystem::path& dir,
                      const std::string& stem) {
  if (final_snapshot.size() == 0) return;
  analysis::SideViewOptions view;
  char extra[128];
  std::snprintf(extra, sizeof extra, "c = %.3g MPa   Pi = %.3g", final_snapshot.tensile_strength_pa / 1e6, pi_group);
  view.title_extra = extra;
  const std::string side = (dir / (stem + "side_view.png")).string();
  if (m.settings.frame != "gate") {
    analysis::write_side_view_png(final_snapshot, side, view, &m);
    return;
  }
  // Measured in the gate frame: the final state is drawn unmarked, and the recorded pattern at
  // the particles' initial positions gets the marks.
  analysis::write_side_view_png(final_snapshot, side, view);
  analysis::SideViewOptions gate_view = view;
  gate_view.title_extra += "   damage at the top of the step, at initial positions";
  analysis::write_side_view_png(analysis::gate_frame_snapshot(final_snapshot),
                                (dir / (stem + "gate_view.png")).string(), gate_view, &m);
}

}  // namespace crevasse
