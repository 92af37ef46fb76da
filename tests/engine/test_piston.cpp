// The piston (docs/model.md: the back face pushed at V_x) must stay behind the ice it pushes: the
// driven layer (particles with a drive_x0) may not move past the rearmost ice on the plateau.
// docs/model.md, "The piston leaks into thick ice", has the measurements.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>

#include "engine/simulation.hpp"
#include "scene_builders.hpp"

namespace crevasse {
namespace {

// How far the driven layer's front has gone past the rearmost non-driven ice on the plateau
// [m] (≤ 0: still behind it), at the worst of the sampled times up to t_end.
double worst_piston_lead(const test::SmallGlacier& g, double t_end) {
  SceneConfig scene = test::small_glacier_scene(g);
  scene = test::finish(scene);
  Simulation<2> sim(scene);
  sim.settle();
  double worst = -std::numeric_limits<double>::infinity();
  double next = 0.0;
  while (sim.time() < t_end) {
    sim.step();
    if (sim.time() < next) continue;
    next += t_end / 20.0;
    const auto& P = sim.particles();
    double layer_front = -std::numeric_limits<double>::infinity();
    double rear_ice = std::numeric_limits<double>::infinity();
    for (std::size_t p = 0; p < P.size(); ++p) {
      if (!std::isnan(P.drive_x0[p]))
        layer_front = std::max(layer_front, P.x[p][0]);
      else if (P.x[p][1] > scene.step_height && P.x[p][0] < scene.gate_x())
        rear_ice = std::min(rear_ice, P.x[p][0]);
    }
    if (std::isfinite(rear_ice)) worst = std::max(worst, layer_front - rear_ice);
  }
  return worst;
}

// A glacier of thickness h [m] with `upstream` and `downstream` H_i of slab and floor
// (H_i/dx = 10), as the studies run it.
test::SmallGlacier glacier(double h, double upstream, double downstream) {
  test::SmallGlacier g;
  g.thickness = h;
  g.cells_per_thickness = 10.0;
  g.upstream_ratio = upstream;
  g.downstream_ratio = downstream;
  return g;
}

// H_i = 100 m (the shipped thickness and slab, 5 H_i): the layer stays behind the ice.
// Measured: its front stays 4.5 m (the layer's particle spacing) behind the rearmost ice
// over the first 50 s (and to the end of the shipped run, 140 s).
TEST(Piston, StaysBehindTheIceAtHundredMetres) {
  const double lead = worst_piston_lead(glacier(100.0, 5.0, 1.0), 50.0);
  std::cout << "H_i = 100 m: layer front minus rearmost ice, worst " << lead << " m\n";
  EXPECT_LT(lead, 0.0);
}

// DISABLED, known defect (engine 0.3.1): at H_i = 800 m with the main study's 6 H_i of slab
// the basal friction the piston must overcome is ~4 MPa, the nodes at the layer's front lag
// V_x, and the layer moves into the ice: 250 m past the rearmost ice by t = 800 s and 450 m by
// 1280 s in that geometry (docs/model.md); in this scene 876 m by t = 900 s (measured). This
// is the acceptance test of a piston that holds.
TEST(Piston, DISABLED_StaysBehindTheIceAtEightHundredMetres) {
  const double lead = worst_piston_lead(glacier(800.0, 6.0, 3.0), 900.0);
  std::cout << "H_i = 800 m: layer front minus rearmost ice, worst " << lead << " m\n";
  EXPECT_LT(lead, 0.0);
}

}  // namespace
}  // namespace crevasse
