#pragma once
// The ice at t = 0: particles on a regular lattice (optionally jittered) over the scene's body,
// draped over the bed when the scene says so, loaded with the geostatic (or hydrostatic) stress
// through the inverse Hencky law.
#include "engine/bed.hpp"
#include "engine/hencky.hpp"
#include "engine/particles.hpp"
#include "engine/scene.hpp"

namespace crevasse {

// `bed` may be null (box scenes). The plastic state is zeroed when the scene is plastic; the
// piston's layer (drive_x0) is marked when the scene is driven by the piston.
template <int Dim>
Particles<Dim> seed_ice(const SceneConfig& scene, const ElasticModuli& moduli, const Bed* bed);

}  // namespace crevasse
