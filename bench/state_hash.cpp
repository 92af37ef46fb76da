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

namespace {

std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t h = 1469598103934665603ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

template <class T>
std::uint64_t hash_array(const std::vector<T>& a) {
  return fnv1a(a.data(), a.size() * sizeof(T));
}

template <int Dim>
int run(const crevasse::SceneConfig& scene, long steps) {
  crevasse::Simulation<Dim> sim(scene);
  sim.settle();
  for (long s = 0; s < steps; ++s) sim.step();
  const auto& P = sim.particles();
  std::uint64_t all = 1469598103934665603ull;
  const auto show = [&](const char* name, std::uint64_t h) {
    std::printf("%-8s %016llx\n", name, static_cast<unsigned long long>(h));
    all = fnv1a(&h, sizeof h, all);
  };
  show("x", hash_array(P.x));
  show("v", hash_array(P.v));
  show("C", hash_array(P.C));
  show("F_e", hash_array(P.F_e));
  show("tau", hash_array(P.tau));
  show("mass", hash_array(P.mass));
  show("eps_v_p", hash_array(P.eps_v_p));
  const double t = sim.time();
  show("time", fnv1a(&t, sizeof t));
  long damaged = 0;
  for (double e : P.eps_v_p) damaged += e > 0.0;
  std::printf("particles %zu, steps %lld, t = %.6f s, damaged %ld\nall      %016llx\n", P.size(),
              static_cast<long long>(sim.steps()), t, damaged, static_cast<unsigned long long>(all));
  // What the state arrays do not hold: the gate's records (archive included, through the
  // snapshot) and the read-outs, so that moving those parts of the engine is checked too.
  const crevasse::ParticleSnapshot snap = sim.snapshot();
  std::uint64_t gate = hash_array(snap.gate_x_ref);
  gate = fnv1a(snap.gate_z_ref.data(), snap.gate_z_ref.size() * sizeof(double), gate);
  gate = fnv1a(snap.gate_eps_v_p.data(), snap.gate_eps_v_p.size() * sizeof(double), gate);
  const double reads[] = {snap.gate_passed_length_m, sim.removed_mass(), sim.inflow_mass(),
                          sim.total_mass(), sim.kinetic_energy(), sim.gravitational_potential_energy(),
                          sim.cap_dissipated_energy(), sim.max_yield_violation(), sim.front_x(),
                          sim.ice_front_x(), sim.max_speed(), sim.last_dt()};
  std::printf("gate     %016llx (%zu records)\nreadouts %016llx\n", static_cast<unsigned long long>(gate),
              snap.gate_eps_v_p.size(), static_cast<unsigned long long>(fnv1a(reads, sizeof reads)));
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
