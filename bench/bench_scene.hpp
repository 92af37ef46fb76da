#pragma once
// The scene every benchmark runs: a block of ice resting on a flat bed under
// gravity, confined laterally by free-slip walls, with the geostatic initial stress (so it is
// near equilibrium from the first step, like a settled glacier) and no settling phase. Elastic:
// gravity, basal friction and walls only; softening adds the capped von Mises return mapping
// with the softening cap. bench_limit seeds its particles from the same scene, so both
// programs run the same particle count in the same order.
#include <cstdint>
#include <string>

#include "engine/scene.hpp"

namespace crevasse::bench {

enum class Material { elastic, softening };

inline const char* material_name(Material m) {
  return m == Material::elastic ? "elastic" : "softening";
}

// 2D: 500 m × 125 m at dx = 1 m, 2×2 particles per cell → 250,000 particles.
// 3D: 64 m × 16 m × 10 m at dx = 1 m, 2×2×2 per cell → 81,920 particles. The block is long in
// x, as a glacier is, so the x-slab colouring of P2G has enough slabs for two threads.
inline SceneConfig block_scene(int dim, Material material) {
  SceneConfig s;
  s.name = std::string("bench_block_") + std::to_string(dim) + "d_" + material_name(material);
  s.dim = dim;
  s.effects = {Effect::gravity, Effect::basal_friction, Effect::box_walls};
  if (material == Material::softening) {
    s.effects.push_back(Effect::plasticity);
    s.effects.push_back(Effect::softening);
  }
  s.body = Body::box;
  s.bed_shape = BedShape::flat;
  s.flat_bed_z = 0.0;
  s.initial_stress = InitialStress::geostatic;
  s.settle_time = 0.0;
  s.dx = 1.0;
  s.particles_per_cell_axis = 2;
  s.max_steps = 1000000000;
  if (dim == 2) {
    s.box_min = {0.0, 0.0, 0.0};
    s.box_max = {500.0, 125.0, 0.0};
    s.domain_min = {0.0, -3.0, 0.0};
    s.domain_max = {500.0, 131.0, 0.0};
    s.wall_axes = {0};
  } else {
    s.box_min = {0.0, 0.0, 0.0};
    s.box_max = {64.0, 16.0, 10.0};
    s.domain_min = {0.0, 0.0, -3.0};
    s.domain_max = {64.0, 16.0, 16.0};
    s.wall_axes = {0, 1};
  }
  s.resolve();
  return s;
}

// Measured steps per repetition: about 5 million particle-steps, so one repetition of the
// slowest case (3D, one thread) stays within a few seconds.
inline std::int64_t measured_steps(int dim) { return dim == 2 ? 20 : 60; }
// Steps run before timing: the first step sorts the particles and touches the grid pages.
constexpr int kWarmupSteps = 3;

}  // namespace crevasse::bench
