#pragma once
// The side views of one finished run: the final state, and in the gate frame the recorded
// damage at the particles' initial positions with the counted crevasses numbered.
#include <filesystem>
#include <string>

#include "analysis/crevasse_measure.hpp"
#include "engine/scene.hpp"
#include "engine/snapshot.hpp"

namespace crevasse {

// Writes <stem>side_view.png, and <stem>gate_view.png when m was measured in the gate frame;
// the view with the marks is the one m was measured on. Nothing for an empty snapshot.
void write_case_views(const SceneConfig& scene, const ParticleSnapshot& final_snapshot,
                      const analysis::CrevasseMeasurement& m, const std::filesystem::path& dir,
                      const std::string& stem = "");
// The same for a snapshot read back from a particle file: the title carries c and this Π.
void write_case_views(double pi_group, const ParticleSnapshot& final_snapshot,
                      const analysis::CrevasseMeasurement& m, const std::filesystem::path& dir,
                      const std::string& stem = "");

}  // namespace crevasse
