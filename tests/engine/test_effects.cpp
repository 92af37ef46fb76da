// docs/model.md: the step is assembled from exactly the effects a scene names. An effect not named
// adds no stage and no per-particle storage; an elastic scene never runs the return mapping.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "engine/simulation.hpp"
#include "scene_builders.hpp"

namespace crevasse {
namespace {

using test::box_scene;
using test::finish;
using test::has_stage;

SceneConfig block(std::initializer_list<Effect> effects) {
  SceneConfig s = box_scene(2, {0, 0, 0}, {6, 3, 0}, {0, -3, 0}, {6, 8, 0}, effects, 1.0);
  s.bed_shape = BedShape::flat;
  s.wall_axes = {0};
  return finish(s);
}

TEST(Effects, ElasticSceneRunsNoReturnMapping) {
  Simulation<2> sim(block({Effect::gravity, Effect::basal_friction}));
  for (int i = 0; i < 20; ++i) sim.step();
  EXPECT_EQ(sim.return_map_evaluations(), 0);
  EXPECT_FALSE(has_stage(sim.stages(), "g2p_return_mapping"));
  EXPECT_TRUE(has_stage(sim.stages(), "g2p_elastic"));
  EXPECT_FALSE(sim.particles().has_plastic_state());  // no ε_v^p storage
  EXPECT_EQ(sim.cap_dissipated_energy(), 0.0);
}

TEST(Effects, PlasticSceneRunsTheReturnMappingOnEveryParticleEveryStep) {
  Simulation<2> sim(block({Effect::gravity, Effect::basal_friction, Effect::plasticity}));
  const int steps = 20;
  for (int i = 0; i < steps; ++i) sim.step();
  EXPECT_TRUE(has_stage(sim.stages(), "g2p_return_mapping"));
  EXPECT_FALSE(has_stage(sim.stages(), "g2p_elastic"));
  EXPECT_EQ(sim.return_map_evaluations(),
            static_cast<std::int64_t>(steps) * static_cast<std::int64_t>(sim.particles().size()));
  EXPECT_TRUE(sim.particles().has_plastic_state());
}

// A plastic scene whose strengths are never reached computes exactly what the elastic one does:
// the return mapping adds cost, never a change, inside the elastic domain.
TEST(Effects, UnreachedPlasticityGivesTheElasticResultBitForBit) {
  SceneConfig elastic = block({Effect::gravity, Effect::basal_friction, Effect::box_walls});
  SceneConfig plastic =
      block({Effect::gravity, Effect::basal_friction, Effect::box_walls, Effect::plasticity});
  plastic.tensile_strength = 1e9;
  plastic.shear_strength = 1e10;
  Simulation<2> a(elastic), b(plastic);
  for (int i = 0; i < 200; ++i) {
    a.step();
    b.step();
  }
  ASSERT_EQ(a.particles().size(), b.particles().size());
  for (std::size_t p = 0; p < a.particles().size(); ++p) {
    EXPECT_EQ(a.particles().x[p], b.particles().x[p]);
    EXPECT_EQ(a.particles().tau[p], b.particles().tau[p]);
  }
  EXPECT_GT(b.return_map_evaluations(), 0);
}

TEST(Effects, StagesFollowTheEffectList) {
  Simulation<2> bare(block({}));
  const auto& st = bare.stages();
  const auto has_effect = [](const auto& sim, const std::string& name) {
    const auto& e = sim.particle_effects();
    return std::find(e.begin(), e.end(), name) != e.end();
  };
  for (const char* absent :
       {"basal_friction", "bed_projection", "box_walls", "lateral_walls", "velocity_boundaries",
        "drive", "outflow", "settle_damping", "grid_velocity_gravity", "g2p_return_mapping"}) {
    EXPECT_FALSE(has_stage(st, absent)) << absent;
    EXPECT_FALSE(has_effect(bare, absent)) << absent;
  }
  EXPECT_TRUE(has_stage(st, "grid_velocity"));  // no gravity term
  // The clamp is always applied, by the update sweep to each particle.
  EXPECT_EQ(bare.particle_effects(), std::vector<std::string>{"domain_clamp"});

  SceneConfig full_scene =
      block({Effect::gravity, Effect::basal_friction, Effect::box_walls,
             Effect::velocity_boundaries, Effect::outflow, Effect::plasticity, Effect::softening});
  Simulation<2> full(full_scene);
  for (const char* present :
       {"basal_friction", "box_walls", "velocity_boundaries", "outflow",
        "grid_velocity_gravity", "g2p_return_mapping"}) {
    EXPECT_TRUE(has_stage(full.stages(), present)) << present;
  }
  EXPECT_EQ(full.particle_effects(), (std::vector<std::string>{"bed_projection", "domain_clamp"}));
  EXPECT_FALSE(has_stage(full.stages(), "lateral_walls"));  // 3D only, and not named
  EXPECT_FALSE(has_stage(full.stages(), "drive"));
  EXPECT_FALSE(has_effect(full, "drive"));
  full.step();
  for (const auto& s : full.stages()) EXPECT_EQ(s.calls, 1) << s.name;
}

// The domain clamp, applied by the update sweep to each particle: a block thrown at 50 m/s
// towards the far face of a domain without walls or outflow piles up on that face and never
// passes it (without the clamp the front ends ~3 m beyond x = 20 m).
TEST(Effects, DomainClampKeepsEveryParticleInsideTheDomain) {
  SceneConfig s = box_scene(2, {0, 0, 0}, {10, 2, 0}, {-2, -2, 0}, {20, 6, 0}, {}, 1.0);
  s = finish(s);
  Simulation<2> sim(s);
  for (auto& v : sim.mutable_particles().v) v[0] = 50.0;
  double front = -1e300;
  for (int i = 0; i < 800; ++i) {
    sim.step();
    for (const auto& x : sim.particles().x) {
      ASSERT_LE(x[0], 20.0) << "step " << i;
      ASSERT_GE(x[0], -2.0) << "step " << i;
      ASSERT_LE(x[1], 6.0) << "step " << i;
      ASSERT_GE(x[1], -2.0) << "step " << i;
      front = std::max(front, x[0]);
    }
  }
  EXPECT_EQ(front, 20.0);  // the block reached the face
}

TEST(Effects, LateralWallsOnlyIn3dWhenNamed) {
  SceneConfig s =
      box_scene(3, {0, 0, 0}, {4, 2, 2}, {0, 0, -2}, {4, 2, 6}, {Effect::lateral_walls}, 1.0);
  Simulation<3> sim(finish(s));
  EXPECT_TRUE(has_stage(sim.stages(), "lateral_walls"));
}

TEST(Effects, DriveStorageOnlyWithDrive) {
  Simulation<2> without(block({Effect::gravity}));
  EXPECT_TRUE(without.particles().drive_x0.empty());
}

// Settling runs only for a geostatic start under gravity, and its damping stage only then.
TEST(Effects, SettlingOnlyForGeostaticStartUnderGravity) {
  SceneConfig geo = block({Effect::gravity, Effect::basal_friction});
  geo.initial_stress = InitialStress::geostatic;
  geo.settle_time = -1.0;
  geo = finish(geo);
  EXPECT_GT(geo.settle_time, 0.0);
  Simulation<2> sim(geo);
  EXPECT_TRUE(has_stage(sim.stages(), "settle_damping"));
  sim.settle();
  EXPECT_EQ(sim.time(), 0.0);  // the clock starts after settling
  EXPECT_EQ(sim.steps(), 0);

  SceneConfig none = block({Effect::gravity, Effect::basal_friction});
  EXPECT_EQ(none.settle_time, 0.0);
}

// Without gravity nothing moves a block at rest: no hidden body force.
TEST(Effects, NoGravityNoMotion) {
  Simulation<2> sim(block({Effect::basal_friction}));
  for (int i = 0; i < 50; ++i) sim.step();
  EXPECT_EQ(sim.kinetic_energy(), 0.0);
}

}  // namespace
TEST(Effects, VolumeAveragingIsANumericsChoiceWithItsOwnStages) {
  // Default on: the step gathers velocities, averages ΔJ, then updates the material.
  Simulation<2> on(block({Effect::plasticity}));
  EXPECT_TRUE(has_stage(on.stages(), "g2p_velocity"));
  EXPECT_TRUE(has_stage(on.stages(), "volume_averaging"));
  EXPECT_TRUE(has_stage(on.stages(), "g2p_return_mapping"));
  SceneConfig off_scene = block({Effect::plasticity});
  off_scene.volumetric_averaging = false;
  Simulation<2> off(off_scene);
  EXPECT_FALSE(has_stage(off.stages(), "g2p_velocity"));
  EXPECT_FALSE(has_stage(off.stages(), "volume_averaging"));
  EXPECT_TRUE(has_stage(off.stages(), "g2p_return_mapping"));
}

}  // namespace crevasse

namespace crevasse {
namespace {

// Ice pushed into the rock comes back out within the step, wherever it is: the bed projection's
// shortcut (a per-column height above which nothing is looked up) must never skip a particle
// that is inside. The bottom row of a glacier's slab is moved a quarter or a half cell into the
// plateau; after one step every one of them is outside the rock to round-off (the table is
// bilinear, exact on the flat plateau, which is why particles near the step's edge are not
// checked).
TEST(Effects, BedProjectionLiftsEveryParticleOutOfTheRock) {
  test::SmallGlacier g;
  g.cells_per_thickness = 8.0;
  Simulation<2> sim(test::small_glacier_scene(g));
  const Bed& bed = *sim.bed();
  const double dx = sim.scene().dx;
  auto& P = sim.mutable_particles();
  // The particles of the lowest row.
  double z_min = P.x[0][1];
  for (const auto& x : P.x) z_min = std::min(z_min, x[1]);
  std::vector<std::size_t> moved;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (P.x[p][1] > z_min + 1e-9) continue;
    const double depth = (0.25 + 0.25 * static_cast<double>(moved.size() % 2)) * dx;
    P.x[p][1] -= bed.signed_distance(P.x[p][0], P.x[p][1]) + depth;  // to depth below the surface
    moved.push_back(p);
  }
  ASSERT_GT(moved.size(), 10u);
  for (std::size_t p : moved) ASSERT_LT(bed.signed_distance(P.x[p][0], P.x[p][1]), -0.2 * dx);
  sim.step();
  const double x_step = g.upstream_ratio * g.thickness;  // the plateau's edge
  const double x_foot = x_step + g.thickness * g.step_length_ratio;
  int checked = 0;
  for (std::size_t p : moved) {
    const Vec<2>& x = sim.particles().x[p];
    if (std::abs(x[0] - x_step) < 2 * dx || std::abs(x[0] - x_foot) < 2 * dx) continue;
    EXPECT_GT(bed.signed_distance(x[0], x[1]), -1e-6 * dx) << "particle " << p << " at x = " << x[0];
    ++checked;
  }
  EXPECT_GT(checked, 10);
}

}  // namespace
}  // namespace crevasse
