// state_hash SCENE.json STEPS [THREADS]: runs a scene file for STEPS steps (after its settling)
// and prints a 64-bit FNV-1a hash of every particle array, bit for bit. Two engine builds that
// print the same hashes for the same scene gave the same results to the last bit: the check an
// optimisation that must not change round-off has to pass (docs/performance.md).
#include <tbb/global_control.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/scene.hpp"
#include "engine/simulation.hpp"
#include "engine/state_hash.hpp"

namespace {

template <int Dim>
int run(const crevasse::SceneConfig& scene, long steps) {
  crevasse::Simulation<Dim> sim(scene);
  sim.settle();
  for (long s = 0; s < steps; ++s) sim.step();
  const crevasse::StateHash h = crevasse::state_hash(sim);
  for (const auto& [name, value] : h.parts)
    std::printf("%-8s %016llx\n", name.c_str(), static_cast<unsigned long long>(value));
  std::printf("particles %zu, steps %lld, t = %.6f s, damaged %ld\nall      %016llx\n",
              sim.particles().size(), static_cast<long long>(sim.steps()), sim.time(), h.damaged,
              static_cast<unsigned long long>(h.all));
  std::printf("gate     %016llx (%zu records)\nreadouts %016llx\n", static_cast<unsigned long long>(h.gate),
              h.gate_records, static_cast<unsigned long long>(h.readouts));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: state_hash SCENE.json STEPS [THREADS]\n");
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in) {
    std::fprintf(stderr, "state_hash: cannot read %s\n", argv[1]);
    return 2;
  }
  const crevasse::SceneConfig scene = crevasse::scene_from_json(nlohmann::json::parse(in));
  const long steps = std::stol(argv[2]);
  const int threads = argc > 3 ? std::stoi(argv[3]) : 1;
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  return scene.dim == 3 ? run<3>(scene, steps) : run<2>(scene, steps);
}
