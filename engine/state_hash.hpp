#pragma once
// A 64-bit FNV-1a hash of a simulation's whole state, bit for bit: every particle array, the
// time, the gate's records and the read-outs. Two engine builds that give the same hashes for the
// same scene and steps computed the same results to the last bit, the check a change that must
// not move round-off has to pass (docs/performance.md, "Bit identity"; bench/state_hash.cpp).
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "engine/simulation.hpp"

namespace crevasse {

struct StateHash {
  std::vector<std::pair<std::string, std::uint64_t>> parts;  // x, v, C, F_e, tau, mass, eps_v_p, time
  std::uint64_t all = 0;                                     // the parts' hashes, hashed in order
  std::uint64_t gate = 0;                                    // the gate's records
  std::size_t gate_records = 0;
  std::uint64_t readouts = 0;  // masses, energies, front, speed, dt
  long damaged = 0;            // particles with eps_v_p > 0
};

inline std::uint64_t fnv1a(const void* data, std::size_t bytes,
                           std::uint64_t h = 1469598103934665603ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

template <int Dim>
StateHash state_hash(const Simulation<Dim>& sim) {
  const auto of = [](const auto& a, std::uint64_t h = 1469598103934665603ull) {
    return fnv1a(a.data(), a.size() * sizeof(a[0]), h);
  };
  const auto& P = sim.particles();
  StateHash s;
  const double t = sim.time();
  s.parts = {{"x", of(P.x)},     {"v", of(P.v)},       {"C", of(P.C)},
             {"F_e", of(P.F_e)}, {"tau", of(P.tau)},   {"mass", of(P.mass)},
             {"eps_v_p", of(P.eps_v_p)}, {"time", fnv1a(&t, sizeof t)}};
  s.all = 1469598103934665603ull;
  for (const auto& [name, h] : s.parts) s.all = fnv1a(&h, sizeof h, s.all);
  for (double e : P.eps_v_p) s.damaged += e > 0.0;
  // What the state arrays do not hold, so that moving those parts of the engine is checked too.
  const ParticleSnapshot snap = sim.snapshot();
  s.gate = of(snap.gate_eps_v_p, of(snap.gate_z_ref, of(snap.gate_x_ref)));
  s.gate_records = snap.gate_eps_v_p.size();
  const double reads[] = {snap.gate_passed_length_m, sim.removed_mass(), sim.inflow_mass(),
                          sim.total_mass(), sim.kinetic_energy(), sim.gravitational_potential_energy(),
                          sim.cap_dissipated_energy(), sim.max_yield_violation(), sim.front_x(),
                          sim.ice_front_x(), sim.max_speed(), sim.last_dt()};
  s.readouts = fnv1a(reads, sizeof reads);
  return s;
}

}  // namespace crevasse
