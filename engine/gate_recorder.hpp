#pragma once
// The measurement gate (docs/measurement.md, "Gate frame"): each particle's ε_v^p at the moment
// it first reaches x ≥ gate_x, kept with its initial position, including particles the outflow
// has since removed (the archive). Per-particle records live in Particles (x_ref, gate_eps), so
// that the sort and the outflow carry them along; the recorder owns the rest.
#include <array>
#include <vector>

#include "engine/particles.hpp"
#include "engine/snapshot.hpp"

namespace crevasse {

template <int Dim>
class GateRecorder {
 public:
  // gate_eps of a particle not recorded yet, and of one that started past the gate; recorded
  // values are ε_v^p ≥ 0.
  static constexpr float kNotYet = -1.0f, kNever = -2.0f;

  // Records of particles since removed: initial position, ε_v^p at the gate.
  struct Archive {
    std::vector<std::array<float, Dim>> x;
    std::vector<float> eps;
  };

  GateRecorder() = default;
  // Marks every particle: ice that starts past the gate (a draped glacier) never passes it, so
  // only ice that crosses the gate is recorded and counted in the passed length.
  GateRecorder(Particles<Dim>& P, double gate_x);

  // Records the particles that have reached the gate since the last call.
  void record(Particles<Dim>& P);
  // Archives the records of the particles about to be removed (keep[p] == 0).
  void archive_removed(const Particles<Dim>& P, const std::vector<char>& keep, std::size_t first = 0);
  // The records of a particle entering through the inflow at `pos`, the drive having moved by
  // `drive_shift` since t = 0.
  static void add_entering(Particles<Dim>& P, const Vec<Dim>& pos, double drive_shift);

  // The ice length along flow that has reached the gate: Σ V0 recorded / the slab's cross-section [m].
  double passed_length() const { return passed_volume_ / cross_section_; }
  void add_to(ParticleSnapshot& s, const Particles<Dim>& P) const;

  // Checkpoints: the state that is not recomputed from the initial ice.
  double passed_volume() const { return passed_volume_; }
  const Archive& archive() const { return archive_; }
  void restore(double passed_volume, Archive archive) {
    passed_volume_ = passed_volume;
    archive_ = std::move(archive);
  }

 private:
  double gate_x_ = 0.0;
  double passed_volume_ = 0.0;  // Σ V0 of every particle recorded
  double cross_section_ = 1.0;  // slab V0 per unit length along flow [m^(Dim−1)]
  Archive archive_;
};

extern template class GateRecorder<2>;
extern template class GateRecorder<3>;

}  // namespace crevasse
