// Scene files are refused, with an InputError naming the field, when they contain unknown keys,
// values of the wrong type or values outside the allowed range (docs/study_format.md: validation errors name
// the field and the allowed range).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "engine/error.hpp"
#include "engine/scene.hpp"

namespace crevasse {
namespace {

using nlohmann::json;

json valid_scene() {
  return json{{"dim", 2},
              {"effects", {"gravity", "drive", "basal_friction", "plasticity", "softening"}},
              {"ice", {{"thickness", 100.0}}},
              {"numerics", {{"dx", 10.0}}},
              {"run", {{"end_time", 1.0}}}};
}

// Expects scene_from_json(j) to throw an InputError whose message contains `field`.
void expect_refused(const json& j, const std::string& field) {
  try {
    scene_from_json(j);
    ADD_FAILURE() << "accepted: " << j.dump();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos)
        << "message '" << e.what() << "' does not name " << field;
  }
}

TEST(SceneValidation, ValidSceneIsAcceptedAndRoundTrips) {
  const SceneConfig s = scene_from_json(valid_scene());
  EXPECT_EQ(s.ice_thickness, 100.0);
  EXPECT_EQ(s.upstream_length, 500.0);        // default 5·H_i
  EXPECT_DOUBLE_EQ(s.softening_zeta, 500.0);  // ζ_ref at dx = dx_ref
  // The canonical JSON reads back to the same canonical JSON.
  const json canonical = scene_to_json(s);
  EXPECT_EQ(scene_to_json(scene_from_json(canonical)), canonical);
}

TEST(SceneValidation, UnknownKeysAreRefused) {
  json j = valid_scene();
  j["gravty"] = {{"g", 9.81}};
  expect_refused(j, "gravty");
  j = valid_scene();
  j["ice"]["thicknes"] = 50.0;
  expect_refused(j, "ice.thicknes");
  j = valid_scene();
  j["ice"]["softening"] = {{"zeta_reference", 500.0}};
  expect_refused(j, "ice.softening.zeta_reference");
  j = valid_scene();
  j["effects"].push_back("magnetism");
  expect_refused(j, "effects");
}

TEST(SceneValidation, WrongTypesAreRefused) {
  json j = valid_scene();
  j["ice"]["density"] = "917";
  expect_refused(j, "ice.density");
  j = valid_scene();
  j["numerics"]["particles_per_cell_axis"] = 2.5;
  expect_refused(j, "numerics.particles_per_cell_axis");
  j = valid_scene();
  j["output"] = {{"png", "yes"}};
  expect_refused(j, "output.png");
  j = valid_scene();
  j["ice"] = 3;
  expect_refused(j, "ice");
  j = valid_scene();
  j["effects"] = "gravity";
  expect_refused(j, "effects");
}

TEST(SceneValidation, PoissonRatioMustLieInOpenInterval) {
  for (const double nu : {-1.0, -1.5, 0.5, 0.6}) {
    json j = valid_scene();
    j["ice"]["poisson_ratio"] = nu;
    expect_refused(j, "ice.poisson_ratio");
  }
  for (const double nu : {-0.99, 0.0, 0.499}) {  // just inside is accepted
    json j = valid_scene();
    j["ice"]["poisson_ratio"] = nu;
    EXPECT_NO_THROW(scene_from_json(j)) << nu;
  }
}

TEST(SceneValidation, OutOfRangeValuesAreRefused) {
  struct Case {
    const char* section;
    const char* key;
    json value;
    const char* field;
  };
  const Case cases[] = {
      {"ice", "thickness", 0.0, "ice.thickness"},
      {"ice", "density", 0.0, "ice.density"},
      {"ice", "tensile_strength", 0.0, "ice.tensile_strength"},
      {"ice", "youngs_modulus", -1.0e9, "ice.youngs_modulus"},
      {"numerics", "cfl", 0.0, "numerics.cfl"},
      {"numerics", "particles_per_cell_axis", 0, "numerics.particles_per_cell_axis"},
      {"bed", "friction", -0.1, "bed.friction"},
      {"bed", "shape", "ramp", "bed.shape"},
      {"ice", "initial_stress", "lithostatic", "ice.initial_stress"},
  };
  for (const Case& c : cases) {
    json j = valid_scene();
    j[c.section][c.key] = c.value;
    expect_refused(j, c.field);
  }
}

// A negative thickness is refused with a message naming ice.thickness. (Before the fix,
// resolve() derived the default settle_time = 30·H_i/c_p from the thickness before it checked
// the thickness, and the message named ice.settle_time, a field the user never wrote.)
TEST(SceneValidation, NegativeThicknessIsNamed) {
  json j = valid_scene();
  j["ice"]["thickness"] = -5.0;
  expect_refused(j, "ice.thickness");
}

// dx must resolve the ice: dx ≤ H_i/4.
TEST(SceneValidation, GridTooCoarseForTheIceIsRefused) {
  json j = valid_scene();
  j["numerics"]["dx"] = 25.0;  // exactly H_i/4: allowed
  EXPECT_NO_THROW(scene_from_json(j));
  j["numerics"]["dx"] = 26.0;
  expect_refused(j, "numerics.dx");
}

TEST(SceneValidation, InconsistentEffectsAreRefused) {
  json j = valid_scene();
  j["effects"] = {"softening"};  // softening without plasticity
  expect_refused(j, "effects");
  j = valid_scene();
  j["effects"] = {"gravity", "gravity"};
  expect_refused(j, "effects");
  j = valid_scene();
  j["effects"] = {"lateral_walls"};  // 2D
  expect_refused(j, "effects");
  j = valid_scene();
  j["run"] = json::object();  // no stop condition
  expect_refused(j, "run");
  j = valid_scene();
  j["dim"] = 4;
  expect_refused(j, "dim");
}

}  // namespace
}  // namespace crevasse
