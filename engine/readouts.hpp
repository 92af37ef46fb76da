#pragma once
// What a run reads off the particles besides the step: conservation sums and energies, the ice
// front, the yield check, and the plain snapshot that output and measurement take.
#include "engine/bed.hpp"
#include "engine/capped_von_mises.hpp"
#include "engine/gate_recorder.hpp"
#include "engine/particles.hpp"
#include "engine/scene.hpp"
#include "engine/snapshot.hpp"

namespace crevasse {

template <int Dim>
double total_mass(const Particles<Dim>& P);
template <int Dim>
Vec<Dim> total_momentum(const Particles<Dim>& P);
template <int Dim>
double kinetic_energy(const Particles<Dim>& P);
template <int Dim>
double gravitational_potential_energy(const Particles<Dim>& P, double gravity);
// Energy dissipated by the tensile cap, Σ V0 ∫ c e^{−ζε} dε = Σ V0 (c/ζ)(1 − e^{−ζ ε_v^p}).
template <int Dim>
double cap_dissipated_energy(const Particles<Dim>& P, const CappedVonMisesParams& plastic);
// Largest yield-function value Φ over the particles, normalised by c (≤ ~0 when admissible).
template <int Dim>
double max_yield_violation(const Particles<Dim>& P, const CappedVonMisesParams& plastic);
// Front of the connected ice [m]: walking downstream from the back in columns one cell wide,
// the right edge of the last column holding at least `min_fraction` of a full column of ice
// (H_i thick) before two thinner columns in a row. Scattered debris ahead of the ice does not
// count.
template <int Dim>
double ice_front_x(const Particles<Dim>& P, const SceneConfig& scene, double min_fraction);
// `bed` and `gate` may be null.
template <int Dim>
ParticleSnapshot make_snapshot(const Particles<Dim>& P, const SceneConfig& scene, const CappedVonMisesParams& plastic,
                               double time, const Bed* bed, const GateRecorder<Dim>* gate);

}  // namespace crevasse
