// The engine's results pinned to the bit: the shipped scenes, run for 2000 steps after their
// settling, keep the state hashes the engine gave when they were recorded (docs/performance.md,
// "Bit identity"). A change that moves round-off (another order of a sum, another math function)
// fails here; if it is meant, it bumps the engine version and records the new hashes.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "engine/state_hash.hpp"
#include "scene_builders.hpp"

namespace crevasse {
namespace {

std::string hex(std::uint64_t h) {
  char s[17];
  std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(h));
  return s;
}

StateHash after_2000_steps(const std::string& file) {
  Simulation<2> sim(scene_from_json(test::shipped_scene_json(file)));
  sim.settle();
  for (int s = 0; s < 2000; ++s) sim.step();
  return state_hash(sim);
}

// The piston glacier: elastic ice pushed over the step (nothing damaged yet).
TEST(StateHash, ThePistonGlacierKeepsItsBits) {
  const StateHash h = after_2000_steps("glacier_2d.json");
  EXPECT_EQ(hex(h.all), "875aa495c5245472");
  EXPECT_EQ(hex(h.readouts), "c947a023c274eba2");
}

// The flowing glacier: the gate records the ice that passes.
TEST(StateHash, TheFlowingGlacierKeepsItsBits) {
  const StateHash h = after_2000_steps("flowing_2d.json");
  EXPECT_EQ(hex(h.all), "fac1a29df1997ce9");
  EXPECT_EQ(hex(h.gate), "cb0d16a0eef13034");
  EXPECT_EQ(hex(h.readouts), "d951f6b13594088f");
}

// The pushed glacier the studies run: inflow, the relaxed per-cell average, the softening cap
// with damaged particles, the gate.
TEST(StateHash, ThePushedGlacierKeepsItsBits) {
  const StateHash h = after_2000_steps("pushed_2d.json");
  EXPECT_GT(h.damaged, 0);
  EXPECT_EQ(hex(h.all), "1ae5242264cd00cc");
  EXPECT_EQ(hex(h.gate), "6d752a38144f03e8");
  EXPECT_EQ(hex(h.readouts), "f7e863d0e889c8e0");
}

}  // namespace
}  // namespace crevasse
