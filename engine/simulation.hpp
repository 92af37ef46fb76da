#pragma once
// One explicit MLS-MPM simulation (docs/model.md). It owns all of its state; nothing is shared
// between simulations, so a study may run many at once. The step is a list of named, timed
// stages assembled from the scene's effects in the constructor: an effect the scene does not
// name adds no stage, and the material kernel (elastic or capped von Mises) is chosen once,
// so an elastic scene never runs a return mapping.
#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "engine/bed.hpp"
#include "engine/bed_field.hpp"
#include "engine/bspline.hpp"
#include "engine/capped_von_mises.hpp"
#include "engine/downstream_meter.hpp"
#include "engine/gate_recorder.hpp"
#include "engine/grid.hpp"
#include "engine/hencky.hpp"
#include "engine/inflow.hpp"
#include "engine/nonlocal_opening.hpp"
#include "engine/outflow.hpp"
#include "engine/particle_colouring.hpp"
#include "engine/particle_effects.hpp"
#include "engine/particles.hpp"
#include "engine/readouts.hpp"
#include "engine/scene.hpp"
#include "engine/settling.hpp"
#include "engine/snapshot.hpp"
#include "engine/volume_average.hpp"

namespace crevasse {

struct StageStats {
  std::string name;
  std::int64_t calls = 0;
  double seconds = 0.0;
};

template <int Dim>
class Simulation {
 public:
  explicit Simulation(const SceneConfig& scene);  // scene must be resolve()d

  void step();
  // Runs the settling phase (scene.settle_time) if it has not run yet; step() calls it first.
  // keep_going, when given, is asked after every settling step (the caller's stop flag, time
  // limit and checkpoints); when it returns false the phase pauses and settle() returns false.
  // The next settle() or step() continues it, as does a checkpoint written meanwhile.
  bool settle(const std::function<bool()>& keep_going = {});
  bool settled() const { return settling_.done; }

  double time() const { return time_; }
  double last_dt() const { return dt_; }
  std::int64_t steps() const { return steps_; }
  const SceneConfig& scene() const { return scene_; }
  const Particles<Dim>& particles() const { return particles_; }
  Particles<Dim>& mutable_particles() { return particles_; }  // tests and initial conditions
  // Tests: update 2D particles one at a time (update_particle) instead of in vectorised blocks
  // (update_particles_2d, engine/particle_update.hpp); the two must agree bit for bit.
  void set_per_particle_update(bool on) { per_particle_update_ = on; }
  const std::vector<StageStats>& stages() const { return stages_; }
  // The per-particle effects that the update sweep applies to each particle right after its
  // update, in this order (bed_projection, drive, domain_clamp): they are not stages of their
  // own, and their time is in the update's stage.
  const std::vector<std::string>& particle_effects() const { return particle_effects_; }
  std::int64_t return_map_evaluations() const { return return_map_evaluations_; }
  std::int64_t particle_steps() const { return particle_steps_; }

  // Diagnostics (conservation checks, hard-case assertions; engine/readouts.hpp).
  double total_mass() const { return crevasse::total_mass(particles_); }
  double removed_mass() const { return outflow_.removed_mass(); }
  double inflow_mass() const { return inflow_.mass(); }  // mass that entered through the inflow
  Vec<Dim> total_momentum() const { return crevasse::total_momentum(particles_); }
  double kinetic_energy() const { return crevasse::kinetic_energy(particles_); }
  double gravitational_potential_energy() const {
    return crevasse::gravitational_potential_energy(particles_, scene_.gravity);
  }
  double cap_dissipated_energy() const { return crevasse::cap_dissipated_energy(particles_, plastic_); }
  double front_x() const { return front_x_; }  // most downstream particle, debris included
  // Front of the connected ice; O(particles), the run loop calls it every few steps.
  double ice_front_x(double min_fraction = 0.25) const {
    return crevasse::ice_front_x(particles_, scene_, min_fraction);
  }
  double max_speed() const { return max_speed_; }
  const Bed* bed() const { return bed_.has_value() ? &*bed_ : nullptr; }
  double max_yield_violation() const { return crevasse::max_yield_violation(particles_, plastic_); }
  // Vertical impulse [N·s per unit width in 2D] that whatever ends the domain downstream (held
  // nodes, walls, velocity boxes) has given the ice since the settling phase: the change of
  // vertical grid momentum those boundary stages make in the last cells before the domain's
  // end. Nothing downstream may carry the glacier (docs/model.md). Not checkpointed.
  double downstream_impulse_z() const { return downstream_.impulse_z(); }

  ParticleSnapshot snapshot() const {
    return make_snapshot(particles_, scene_, plastic_, time_, bed(), records_gate() ? &gate_ : nullptr);
  }

  // Checkpoints (engine/checkpoint.hpp): the whole state the next step reads, written atomically
  // (temporary file, then rename). load_checkpoint throws SimulationError when the file is not a
  // checkpoint of this scene and engine version, or is truncated.
  // `wall_s`: what the run has cost so far (nullopt: unknown), kept in the file;
  // load_checkpoint returns it.
  void save_checkpoint(const std::string& path, std::optional<double> wall_s = 0.0) const;
  std::optional<double> load_checkpoint(const std::string& path);

  // Measurement gate at scene.gate_x() (when scene.records_gate()): the ice length along flow
  // that has reached it, Σ V0 of the particles recorded / the slab's cross-section [m].
  bool records_gate() const { return !particles_.gate_eps.empty(); }
  double gate_passed_length() const { return records_gate() ? gate_.passed_length() : 0.0; }

 private:
  struct Stage {
    std::string name;
    std::function<void()> run;
  };
  void add_stage(std::string name, std::function<void()> run);
  // The time step's reduction over the particles: the largest |v|², the front, the first
  // particle with a non-finite velocity or stress.
  struct StepSummary {
    double v2 = 0.0;
    double front = -std::numeric_limits<double>::infinity();
    std::int64_t bad = -1;
  };
  static StepSummary merge(StepSummary a, const StepSummary& b);
  [[gnu::always_inline]] inline void summarise_particle(std::size_t p, StepSummary& acc) const;
  StepSummary summarise_particles() const;
  // The scene's per-particle effects (particle_effects()) with the piston's place and speed at
  // the end of this step.
  ParticleEffects<Dim> particle_effects_now() const;

  // Stages, in step order. Each says what it reads and writes; the grid's boundary conditions
  // (engine/grid_boundaries.hpp) read the nodes' mass and velocity and write the velocity.
  // Every step: re-sorts the particles by cell (every kSortInterval steps), fits the grid's
  // box to them and builds the P2G colouring. Reads x; writes the particle order, grid_ (empty),
  // colouring_.
  void prepare_grid();
  // P2G. Reads x, v, C, τ, mass, V0 (and ε_v^p with the average); writes the nodes' mass,
  // momentum (and intact_mass, and the average's kept softening).
  void particle_to_grid();
  template <bool Average>
  void scatter_to_grid();  // P2G, with the ΔJ-bar average's weights when Average
  // Momentum to velocity, plus gravity. Reads and writes the nodes' velocity.
  void grid_velocity(const Vec<Dim>& gravity);
  double drive_speed_now() const { return settling_.active ? 0.0 : scene_.drive_velocity(time_); }
  // downstream_drive holds the nodes of this many cells upstream of the domain's end (the
  // outflow line is 3 cells from it, so 2 cells of ice before it move at the drive speed).
  static constexpr double kDownstreamDriveCells = 5.0;
  // The ΔJ-bar average (average_) weights each particle by 1 − D (volume_average.hpp).
  bool averaging_weights_damage() const;
  // G2P's update sweep: the particle update (engine/particle_update.hpp), the per-particle
  // effects, the time step's summary. Average: after the ΔJ-bar sweeps (average_); otherwise
  // the velocity gather is fused into it. Reads the grid (velocity, or average_'s averages),
  // every particle array; writes x, v, C, F_E, τ, ε_v^p, summary_ and the clock (finish_step).
  template <bool Plastic, bool Average>
  void update_particles();
  template <bool Plastic>
  void finish_step();
  // The outflow stage (outflow_). Reads x and summary_; compacts every particle array, writes
  // outflow_'s removed mass and the gate's archive.
  void remove_outflow();
  // The inflow stage (inflow_). Reads the clock, x; appends particles, writes inflow_.
  void inflow();
  // The next dt from the CFL condition, and the instability checks. Reads summary_ (or v, τ,
  // x); writes dt_, max_speed_, front_x_; throws SimulationError on an instability.
  void update_time_step();

  // What each particle's softening reads: its own ε_v^p, or the nonlocal ε̂ (nonlocal_), which
  // is not computed while settling (no opening yet). Read once per sweep, not per particle.
  const double* openings_for_softening() const {
    return nonlocal_.active() && !settling_.active ? nonlocal_.values() : particles_.eps_v_p.data();
  }

  SceneConfig scene_;
  ElasticModuli moduli_;
  CappedVonMisesParams plastic_;
  double creep_rate_ = 0.0;  // SceneConfig::creep_rate(); plastic_.creep_increment = Δt·this each step
  Particles<Dim> particles_;
  Grid<Dim> grid_;
  std::optional<Bed> bed_;
  BedField<Dim> bed_field_;  // the bed as contact and projection read it (scenes with a bed)
  GateRecorder<Dim> gate_;   // scenes that record a gate (records_gate())
  bool per_particle_update_ = false;

  std::vector<Stage> stage_fns_;
  std::vector<StageStats> stages_;
  std::vector<std::string> particle_effects_;
  ParticleEffects<Dim> effects_;  // which of them the scene has (the piston's place is per step)
  // The summary the update sweep reduced, for the time step of the same step (steps_ then);
  // stale once the outflow has removed particles.
  StepSummary summary_;
  std::int64_t summary_step_ = -1;
  ParticleColouring<Dim> colouring_;  // the race-free order of P2G-style scatters
  VolumeAverage<Dim> average_;         // numerics.volumetric_averaging
  NonlocalOpening<Dim> nonlocal_;      // ice.softening.nonlocal_radius
  std::vector<double> drive_node_mass_;  // per node: mass from the driven layer (drive_grid)
  Outflow<Dim> outflow_;
  Inflow<Dim> inflow_;
  DownstreamImpulseMeter<Dim> downstream_;  // slab scenes
  Settling settling_;

  Vec<Dim> domain_lo_, domain_hi_;
  double time_ = 0.0;
  double dt_ = 0.0;
  std::int64_t steps_ = 0;
  std::int64_t particle_steps_ = 0;
  std::int64_t return_map_evaluations_ = 0;
  // Largest physically possible particle speed [m/s] (slab scenes with gravity; 0 = none):
  // a faster particle means a numerical instability (update_time_step).
  double speed_bound_ = 0.0;
  double front_x_ = 0.0;
  double max_speed_ = 0.0;
};

extern template class Simulation<2>;
extern template class Simulation<3>;

}  // namespace crevasse
