#pragma once
// A study file (docs/study_format.md): a base scene, fixed parameters and sweep axes
// over the dimensionless groups (or any scene parameter by JSON pointer), replicas,
// measurement settings and resources. Loading it enumerates every case (Cartesian product of
// the axes × replicas), derives the dimensional parameters (c = Π ρ_i g H_i, L_s = r·H_i,
// H_s = S·L_s or h·H_i, W_i = w·H_i), resolves and validates each case's scene, and hashes it.
// Nothing runs until every case has passed: a bad file is refused as a whole.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/crevasse_measure.hpp"
#include "engine/scene.hpp"

namespace crevasse {

// Names a study file may set besides JSON pointers into the scene ("/ice/density").
// Groups (docs/model.md) and lengths in units of H_i.
inline constexpr const char* kStudyParameterNames[] = {
    "thickness",               // H_i [m]
    "cohesion_ratio",          // Π = c / (ρ_i g H_i)
    "shear_strength_ratio",    // q_y / (ρ_i g H_i)
    "shear_to_tensile_ratio",  // k = q_y / c, a material constant
    "draped_length_ratio",     // ice past the lip at the start (over the ramp and floor) / H_i
    "gate_offset_ratio",       // gate past the top of the step / H_i
    "step_length_ratio",       // r = L_s / H_i (0 = vertical step)
    "slope",                   // S = H_s / L_s
    "step_height_ratio",       // h = H_s / H_i (instead of slope; the only choice when r = 0)
    "width_ratio",             // w = W_i / H_i (3D)
    "cells_per_thickness",     // H_i / dx
    "front_past_step_ratio",   // stop when the front is this many H_i past the step foot
    "gate_length_ratio",       // stop when this many H_i of ice have passed the top of the step
    "upstream_length_ratio",   // slab length on the plateau / H_i
    "downstream_length_ratio"  // floor length past the step / H_i
};

struct SweepAxis {
  std::string name;                    // a name above or a JSON pointer
  std::vector<nlohmann::json> values;  // in enumeration order
};

struct StudyResources {
  int jobs = 0;                  // cases at once; 0 = default (see runner.hpp)
  int threads_per_case = 0;      // engine threads per case; 0 = default
  double case_time_limit_s = 0;  // wall seconds per case; 0 = none
  // Wall seconds between checkpoints of a running case (DB.checkpoints/CASE.ckpt), so that a
  // study killed and resumed continues each unfinished case from its last checkpoint; 0 = none.
  double checkpoint_interval_s = 600;
};

// The dimensionless groups of one case as it runs (computed from the resolved scene, so they
// are right whichever way the file set them).
struct CaseGroups {
  double thickness_m = 0.0;
  double cohesion_ratio = 0.0;
  double step_length_ratio = 0.0;
  double step_height_ratio = 0.0;
  std::optional<double> slope;        // absent for a vertical step
  std::optional<double> width_ratio;  // 3D only
};

struct StudyCase {
  std::size_t index = 0;  // position in the enumeration (last axis fastest, replicas innermost)
  std::string label;      // "cohesion_ratio=0.1 thickness=100 replica=1"
  nlohmann::json axes;    // this case's value on every sweep axis (and "replica")
  int replica = 0;
  SceneConfig scene;          // resolved; run.wall_time_limit comes from resources at run time
  nlohmann::json scene_json;  // scene_to_json(scene): canonical, every default explicit
  CaseGroups groups;
  std::string case_id;  // case_hash(): SHA-256 hex
};

struct Study {
  std::string name;
  std::string description;
  std::string source_text;    // the file as given (stored in the database)
  nlohmann::json base_scene;  // the base scene as written (before any override)
  std::vector<std::pair<std::string, nlohmann::json>> fixed;
  std::vector<SweepAxis> axes;
  int replicas = 1;
  std::uint64_t first_seed = 1;
  analysis::MeasureSettings measurement;
  nlohmann::json measurement_json;  // canonical form of `measurement` (enters the case hash)
  StudyResources resources;
  // Which field the study measures (docs/model.md, "Two protocols"): "initiation" (the draped
  // frame, ice that lay over the step when the push began), "steady" (the passed frame, ice that
  // flowed over the lip), or empty for a study that does not say. Labels the database's figures
  // and fits; its frame is the measurement's default and no other frame is accepted with it.
  std::string protocol;
  // > 0: each case also measures its field every this many simulated seconds and stores the
  // series in result_json.extra.over_time, to see when the field settles. Not part of a
  // case's identity: the measurement at the end is the same with or without it.
  double measure_interval_s = 0.0;
  // "keep_particles_at_gate_length_ratios": where a case keeps its particles (--keep-particles)
  // it also keeps them when this much ice, in H_i, has passed the gate, under the id of the case
  // that stops there (run.gate_length = ratio × H_i), for --remeasure. Not part of a case's
  // identity.
  std::vector<double> gate_mark_ratios;
  std::vector<StudyCase> cases;
  std::string study_hash;  // SHA-256 of the sorted case ids: same cases ⇔ same study
};

// Reads and validates a study file; a relative base_scene path is taken from the file's
// directory. Throws InputError naming the field, the value and the allowed range.
Study load_study_file(const std::filesystem::path& path);
// Same from text; `base_dir` resolves a relative base_scene path, `source` names the file in
// messages.
Study parse_study(const std::string& text, const std::filesystem::path& base_dir,
                  const std::string& source = "study");

// Values of one axis specification: a non-empty list, {"linear": [a, b, n]} or
// {"log": [a, b, n]} (n ≥ 1 points including both ends; rounded to 12 significant digits so
// that 0.1 is 0.1). `field` names the axis in error messages.
std::vector<nlohmann::json> expand_axis(const nlohmann::json& spec, const std::string& field);

// Measurement settings from the study's "measurement" object (unknown keys refused), and back.
analysis::MeasureSettings measure_settings_from_json(const nlohmann::json& j);
nlohmann::json measure_settings_to_json(const analysis::MeasureSettings& s);

}  // namespace crevasse
