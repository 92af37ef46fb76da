#include "engine/simulation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cmath>
#include <numbers>
#include <sstream>

#include "engine/bspline.hpp"
#include "engine/checkpoint.hpp"
#include "engine/error.hpp"
#include "engine/fast_math.hpp"
#include "engine/grid_boundaries.hpp"
#include "engine/particle_update.hpp"
#include "engine/seeding.hpp"
#include "engine/velocity_gather.hpp"

namespace crevasse {
namespace {

// Re-sorting particles by cell restores memory locality; every ~100 steps costs ~1% and never
// costs ~17% (docs/performance.md).
constexpr int kSortInterval = 100;
constexpr std::size_t kGrain = 1024;

std::string describe_position(const double* x, int dim) {
  std::ostringstream o;
  o << "(";
  for (int a = 0; a < dim; ++a) o << (a ? ", " : "") << x[a];
  o << ") m";
  return o.str();
}

}  // namespace

template <int Dim>
Simulation<Dim>::Simulation(const SceneConfig& scene) : scene_(scene) {
  if (scene_.dim != Dim) throw InputError("dim: scene is " + std::to_string(scene_.dim) + "D");
  moduli_ = ElasticModuli::from_young_poisson(scene_.youngs_modulus, scene_.poisson_ratio);
  plastic_.tensile_strength_c = scene_.tensile_strength;
  plastic_.shear_strength_qy = scene_.shear_strength;
  plastic_.softening_zeta = scene_.has(Effect::softening) ? scene_.softening_zeta : 0.0;
  plastic_.damage_softens_shear = scene_.damage_softens_shear;
  plastic_.residual_friction_m = scene_.residual_friction;
  plastic_.creep_exponent = scene_.creep_exponent;
  creep_rate_ = scene_.has(Effect::plasticity) ? scene_.creep_rate() : 0.0;
  plastic_.brittle_cap = scene_.brittle_cap;
  if (scene_.has(Effect::softening) && scene_.nonlocal_radius > 0.0) {
    nonlocal_ = NonlocalOpening<Dim>(scene_.nonlocal_radius, scene_.nonlocal_weight, scene_.dx);
    plastic_.explicit_softening = true;
  }
  grid_.dx = scene_.dx;
  domain_lo_ = to_vec<Dim>(scene_.domain_min);
  domain_hi_ = to_vec<Dim>(scene_.domain_max);

  const double x_lo = scene_.domain_min[0], x_hi = scene_.domain_max[0];
  if (scene_.bed_shape == BedShape::step) {
    bed_ = Bed::step(scene_.step_top_x(), scene_.step_height, scene_.step_length, x_lo, x_hi, scene_.lip_radius);
  } else if (scene_.bed_shape == BedShape::concave) {
    bed_ = Bed::concave(scene_.step_top_x(), scene_.step_height, scene_.step_length, x_lo, x_hi);
  } else if (scene_.bed_shape == BedShape::flat) {
    bed_ = Bed::flat(scene_.flat_bed_z, x_lo, x_hi);
  }
  if (bed_) bed_field_ = BedField<Dim>(*bed_, domain_lo_, domain_hi_, scene_.dx);
  particles_ = seed_ice<Dim>(scene_, moduli_, bed_ ? &*bed_ : nullptr);
  if (scene_.records_gate()) gate_ = GateRecorder<Dim>(particles_, scene_.gate_x());
  average_ = VolumeAverage<Dim>(scene_);
  outflow_ = Outflow<Dim>(domain_hi_[0] - 3.0 * scene_.dx);
  inflow_ = Inflow<Dim>(scene_.dx / scene_.particles_per_cell_axis);
  downstream_ = DownstreamImpulseMeter<Dim>(domain_hi_[0] - (kDownstreamDriveCells + 1.0) * scene_.dx);
  if (scene_.body == Body::slab && scene_.has(Effect::gravity)) {
    // No particle of a slab can go faster than free fall from the top of the ice to the floor
    // plus twice the drive (a block pushed off at V_x and rebounding); 1.5× that is a margin
    // that the hard-case suite never approached in stable runs (docs/reliability.md).
    const double v_drive = scene_.has(Effect::drive) ? scene_.drive_speed : 0.0;
    speed_bound_ = 1.5 * (2.0 * v_drive + std::sqrt(2.0 * scene_.gravity *
                                                    (scene_.step_height + scene_.ice_thickness)));
  }

  // Assemble the step from the scene's effects (docs/model.md).
  const double g = scene_.has(Effect::gravity) ? scene_.gravity : 0.0;
  Vec<Dim> gravity = Vec<Dim>::Zero();
  const double tilt = scene_.gravity_tilt_deg * std::numbers::pi / 180.0;
  gravity[0] = g * std::sin(tilt);
  gravity[up_axis<Dim>] = -g * std::cos(tilt);

  add_stage("prepare_grid", [this] { prepare_grid(); });
  // Before P2G, which keeps each particle's softening factor for the update.
  if (nonlocal_.active() && scene_.has(Effect::plasticity))
    add_stage("nonlocal_opening", [this] {
      if (!settling_.active) nonlocal_.compute(particles_, grid_, colouring_);
    });
  add_stage("p2g", [this] { particle_to_grid(); });
  add_stage(g != 0.0 ? "grid_velocity_gravity" : "grid_velocity",
            [this, gravity] { grid_velocity(gravity); });
  const bool has_inflow = scene_.drive_boundary == DriveBoundary::inflow;
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  if (scene_.has(Effect::drive) && !has_inflow) {
    add_stage("drive_grid", [this] { pull_nodes_with_piston(grid_, particles_, drive_speed_now(), drive_node_mass_); });
  }
  if (scene_.has(Effect::basal_friction))
    add_stage("basal_friction", [this] { apply_bed_friction(grid_, bed_field_, scene_.bed_friction); });
  if (has_inflow) {
    // The nodes up to Inflow::kHoldCells from the back move at V(t) along x, free vertically.
    // Every particle within 2.5 cells of the back has its whole stencil on them, so it moves at
    // exactly V(t) and its F_E sees the same velocity field as its position does; the ice ahead
    // is pushed through the grid, and its compression is stress.
    add_stage("inflow_grid", [this] {
      hold_nodes_at_speed(grid_, -kInfinity, Inflow<Dim>::kHoldCells * scene_.dx, drive_speed_now(), false);
    });
  }
  // The boundary stages between these two brackets are the only ones that can act on the
  // downstream band (engine/downstream_meter.hpp). Read the nodes' mass and velocity.
  const bool glacier = scene_.body == Body::slab;
  if (glacier) add_stage("downstream_band_before", [this] { downstream_.before(grid_); });
  if (scene_.has(Effect::downstream_drive)) {
    // The glacier goes on past the domain: the nodes of the last cells before the outflow line
    // move with it, at (V(t), 0) on the flat floor. Without this the floor ice is free to be
    // pushed away by the ice on the ramp, which at μ_b = 0.1 is not held by friction alone
    // (ρ g H_i (H_s − μ_b L_s) down the ramp against μ_b ρ g H_i L_floor on the floor).
    add_stage("downstream_drive", [this] {
      hold_nodes_at_speed(grid_, domain_hi_[0] - kDownstreamDriveCells * scene_.dx, kInfinity, drive_speed_now(), true);
    });
  }
  if (scene_.has(Effect::lateral_walls)) {
    add_stage("lateral_walls", [this] { apply_free_slip_walls(grid_, {1}, domain_lo_, domain_hi_); });
  }
  if (scene_.has(Effect::box_walls)) {
    add_stage("box_walls", [this] { apply_free_slip_walls(grid_, scene_.wall_axes, domain_lo_, domain_hi_); });
  }
  if (scene_.has(Effect::velocity_boundaries))
    add_stage("velocity_boundaries", [this] { apply_velocity_boxes(grid_, scene_.velocity_boxes, time_); });
  if (glacier)
    add_stage("downstream_band_after", [this] {
      if (!settling_.active) downstream_.after(grid_);
    });
  if (scene_.settle_time > 0.0) {
    settling_.damping_rate = Settling::damping_rate_of<Dim>(scene_);
    add_stage("settle_damping", [this] { settling_.damp(grid_, dt_); });  // the nodes' velocity
  }
  const bool plastic = scene_.has(Effect::plasticity);
  // The particle update: with the average, after a sweep that gathers the velocities and
  // scatters the volume change; without, the gather is fused into it.
  const bool average = scene_.volumetric_averaging;
  // The averaging stages read and write what engine/volume_average.hpp says of each.
  if (average) {
    add_stage("g2p_velocity", [this] {
      average_.gather_and_scatter(particles_, grid_, colouring_, dt_, averaging_weights_damage());
    });
    add_stage("volume_averaging", [this] { average_.normalise(grid_); });
    if (scene_.average_per_cell)
      add_stage("cell_average", [this] {
        average_.average_over_cells(particles_, grid_, colouring_, dt_, averaging_weights_damage());
      });
  }
  if (plastic) {
    // No return mapping while settling: the settled state is elastic by construction.
    add_stage("g2p_return_mapping", [this, average] {
      if (average) settling_.active ? update_particles<false, true>() : update_particles<true, true>();
      else settling_.active ? update_particles<false, false>() : update_particles<true, false>();
    });
  } else {
    add_stage("g2p_elastic", [this, average] {
      average ? update_particles<false, true>() : update_particles<false, false>();
    });
  }
  // Applied by the update sweep to each particle as it is written (engine/particle_effects.hpp).
  effects_.bed = scene_.has(Effect::basal_friction);
  effects_.piston = scene_.has(Effect::drive) && !has_inflow;  // the piston's kinematic layer
  effects_.lo = domain_lo_;
  effects_.hi = domain_hi_;
  if (effects_.bed) particle_effects_.push_back("bed_projection");
  if (effects_.piston) particle_effects_.push_back("drive");
  // Particles never leave the domain: the last line of defence, whatever the effects.
  particle_effects_.push_back("domain_clamp");
  if (scene_.records_gate()) add_stage("gate", [this] { gate_.record(particles_); });
  if (scene_.has(Effect::outflow)) add_stage("outflow", [this] { remove_outflow(); });
  if (has_inflow) add_stage("inflow", [this] { inflow(); });
  add_stage("time_step", [this] { update_time_step(); });

  update_time_step();
  // The first step's dt comes from the initial state only: no instability check yet.
}

template <int Dim>
void Simulation<Dim>::add_stage(std::string name, std::function<void()> run) {
  stages_.push_back({name, 0, 0.0});
  stage_fns_.push_back({std::move(name), std::move(run)});
}

template <int Dim>
bool Simulation<Dim>::settle(const std::function<bool()>& keep_going) {
  if (settling_.done) return true;
  if (scene_.settle_time <= 0.0) {
    settling_.done = true;
    return true;
  }
  // settling_.done stays false until the phase ends, so that a checkpoint written while
  // settling (between steps, through keep_going) resumes the phase where it stood.
  settling_.active = true;
  while (time_ < scene_.settle_time) {
    step();
    if (keep_going && !keep_going()) {
      settling_.active = false;
      return false;
    }
  }
  settling_.active = false;
  settling_.done = true;
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    particles_.v[p].setZero();
    particles_.C[p].setZero();
  }
  if (scene_.drive_start == DriveStart::moving) set_sliding(particles_, scene_.drive_speed);
  time_ = 0.0;
  steps_ = 0;
  particle_steps_ = 0;
  return_map_evaluations_ = 0;
  for (auto& st : stages_) st = {st.name, 0, 0.0};
  update_time_step();
  return true;
}

template <int Dim>
void Simulation<Dim>::step() {
  if (!settling_.done && !settling_.active) settle();
  for (std::size_t s = 0; s < stage_fns_.size(); ++s) {
    const auto t0 = std::chrono::steady_clock::now();
    stage_fns_[s].run();
    stages_[s].seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++stages_[s].calls;
  }
}

template <int Dim>
void Simulation<Dim>::prepare_grid() {
  auto& P = particles_;
  const std::size_t n = P.size();
  if (n == 0) {
    grid_.reset(IVec<Dim>::Zero(), IVec<Dim>::Ones());
    colouring_.clear();
    return;
  }
  const double inv_dx = 1.0 / scene_.dx;
  if (steps_ % kSortInterval == 0) {
    // Sort by cell (x slowest) for locality in P2G/G2P. The keys are released before the
    // arrays are reordered (in place), so the step's peak memory is the steady state plus the
    // order and the sort's buffer.
    std::vector<std::uint32_t> order(n);
    {
      std::vector<std::uint64_t> key(n);
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, kGrain), [&](const auto& r) {
        for (std::size_t p = r.begin(); p != r.end(); ++p) {
          std::uint64_t k = 0;
          for (int a = 0; a < Dim; ++a)
            k = (k << 20) | static_cast<std::uint64_t>(static_cast<std::int64_t>(floor_to_int(P.x[p][a] * inv_dx)) + (1 << 19));
          key[p] = k;
        }
      });
      std::iota(order.begin(), order.end(), 0u);
      std::stable_sort(order.begin(), order.end(), [&](auto a, auto b) { return key[a] < key[b]; });
    }
    P.permute(order);
  }
  // Node box covering every particle's stencil.
  using Range = std::pair<IVec<Dim>, IVec<Dim>>;
  const IVec<Dim> big = IVec<Dim>::Constant(std::numeric_limits<int>::max());
  const Range box = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kGrain), Range{big, -big},
      [&](const auto& r, Range acc) {
        for (std::size_t p = r.begin(); p != r.end(); ++p) {
          for (int a = 0; a < Dim; ++a) {
            const int b = floor_to_int(P.x[p][a] * inv_dx - 0.5);
            acc.first[a] = std::min(acc.first[a], b);
            acc.second[a] = std::max(acc.second[a], b + 2);
          }
        }
        return acc;
      },
      [](Range a, const Range& b) {
        return Range{a.first.cwiseMin(b.first), a.second.cwiseMax(b.second)};
      });
  grid_.reset(box.first, (box.second - box.first).array() + 1);

  colouring_.build(P, grid_);
}

template <int Dim>
void Simulation<Dim>::particle_to_grid() {
  if (scene_.volumetric_averaging) scatter_to_grid<true>();
  else scatter_to_grid<false>();
}

template <int Dim>
template <bool Average>
void Simulation<Dim>::scatter_to_grid() {
  const auto& P = particles_;
  const double dx = scene_.dx, inv_dx = 1.0 / dx;
  const double d_inv = 4.0 * inv_dx * inv_dx;  // MLS inertia-like tensor inverse for quadratic B-splines
  const double dt = dt_;
  // With the ΔJ-bar average, each particle also adds its intact mass m (1 − D), the weight of
  // the average, and keeps its e^{−ζ ε_v^p} for the sweeps after (ε_v^p does not change before
  // the update).
  const bool plastic = Average && !P.eps_v_p.empty();
  const bool damage = Average && averaging_weights_damage();
  average_.keep_softening_of(plastic ? P.size() : 0);
  const double* const opening = plastic ? openings_for_softening() : nullptr;
  const std::array<std::size_t, Dim> stride = grid_.strides();
  GridNode<Dim>* const nodes = grid_.nodes.data();
  colouring_.for_each([&](std::uint32_t p) __attribute__((always_inline)) {
    const Vec<Dim> xg = P.x[p] * inv_dx;
    const StencilWeights<Dim> w(xg);
    const double m = P.mass[p];
    // MLS-MPM (Hu et al. 2018): stress enters as an affine momentum term,
    // −dt·V0·τ·D⁻¹ with D⁻¹ = 4/dx² for quadratic B-splines.
    const Mat<Dim> affine = m * P.C[p] - (dt * d_inv * P.vol0[p]) * P.tau[p];
    const Vec<Dim> mv = m * P.v[p];
    double wm = 0.0;
    if constexpr (Average) {
      const double f = plastic ? softening_factor(plastic_, opening[p]) : 1.0;
      if (plastic) average_.keep_softening(p, f);
      wm = average_.weight(P, p, damage);
    }
    // affine·Δx per node from per-axis products, the doubles of affine * Δx (AffineTerms).
    const AffineTerms<Dim> ad(affine, StencilOffsets<Dim>(w, xg, dx));
    for_each_stencil_node<Dim>(w, grid_.flat(w.base()), stride,
                               [&](const IVec<Dim>& off, std::size_t f, double wt) {
      GridNode<Dim>& g = nodes[f];
      g.mass += wt * m;
      if constexpr (Average) g.intact_mass += wt * wm;
      g.vel += wt * (mv + ad.at(off));
    });
  });
}

template <int Dim>
void Simulation<Dim>::grid_velocity(const Vec<Dim>& gravity) {
  const double dt = dt_;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid_.node_count(), kGrain), [&](const auto& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f) {
      if (grid_.nodes[f].mass > 0.0) grid_.nodes[f].vel = grid_.nodes[f].vel / grid_.nodes[f].mass + dt * gravity;
    }
  });
}

template <int Dim>
bool Simulation<Dim>::averaging_weights_damage() const {
  // Broken ice is left out of the average only once it can break: not while settling, not
  // without softening.
  return particles_.has_plastic_state() && plastic_.softening_zeta > 0.0 && !settling_.active;
}

template <int Dim>
ParticleEffects<Dim> Simulation<Dim>::particle_effects_now() const {
  ParticleEffects<Dim> e = effects_;
  if (e.piston && !settling_.active) {
    // The piston's place at the end of this step: finish_step's time_ + dt_.
    const double end_time = time_ + dt_;
    e.piston_shift = scene_.drive_position(end_time);
    e.piston_speed = scene_.drive_velocity(end_time);
  }
  return e;
}

template <int Dim>
template <bool Plastic, bool Average>
void Simulation<Dim>::update_particles() {
  auto& P = particles_;
  const double dx = scene_.dx, inv_dx = 1.0 / dx, c_scale = 4.0 * inv_dx * inv_dx;
  const bool damage = Average && averaging_weights_damage();
  const bool kept_softening = average_.kept_softening();  // P2G kept e^{−ζ ε_v^p} (averaged, plastic)
  const ParticleEffects<Dim> effects = particle_effects_now();
  const double* const opening = Plastic && !Average ? openings_for_softening() : nullptr;
  plastic_.creep_increment = dt_ * creep_rate_;
  if (scene_.cap_relaxation_time > 0.0) {
    const double r = dt_ / scene_.cap_relaxation_time;
    plastic_.cap_relaxed_fraction = r / (1.0 + r);
  }
  // What the update needs of particle p first: with the average, its stencil's sums (its velocity
  // was gathered by average_.gather_and_scatter); without, the gather itself.
  const auto inputs = [&](std::size_t p, double& jbar, double& wsum, double& dj,
                          double& soft) __attribute__((always_inline)) {
    const Vec<Dim> xg = P.x[p] * inv_dx;
    const StencilWeights<Dim> w(xg);
    if constexpr (Average) {
      const typename VolumeAverage<Dim>::Sums v = average_.sums(P, grid_, p, w, dt_);
      jbar = v.jbar;
      wsum = v.wsum;
      dj = v.dj;
      soft = kept_softening ? average_.softening(p) : 1.0;
    } else {
      gather_velocity(P, grid_, p, w, StencilOffsets<Dim>(w, xg, dx), grid_.flat(w.base()), c_scale);
      soft = Plastic ? softening_factor(plastic_, opening[p]) : 1.0;
    }
  };
  summary_ = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, P.size(), kGrain), StepSummary{},
      [&](const auto& r, StepSummary acc) {
        const auto finish = [&](std::size_t p) __attribute__((always_inline)) {
          effects.apply(P, p, bed_field_);
          summarise_particle(p, acc);
        };
        if constexpr (Dim == 2) {
          if (!per_particle_update_) {
            update_particles_2d<Plastic, Average>(P, r.begin(), r.end(), dt_, damage, moduli_, plastic_, inputs, finish);
            return acc;
          }
        }
        for (std::size_t p = r.begin(); p != r.end(); ++p) {
          double jbar = 0.0, wsum = 0.0, dj = 1.0, soft = 1.0;
          inputs(p, jbar, wsum, dj, soft);
          const double scale = Average ? volume_scale_of(jbar, wsum, dj, damage ? soft : 1.0) : 1.0;
          update_particle<Dim, Plastic>(P, p, dt_, scale, soft, moduli_, plastic_);
          finish(p);
        }
        return acc;
      },
      merge);
  finish_step<Plastic>();
}

template <int Dim>
template <bool Plastic>
void Simulation<Dim>::finish_step() {
  if constexpr (Plastic) return_map_evaluations_ += static_cast<std::int64_t>(particles_.size());
  particle_steps_ += static_cast<std::int64_t>(particles_.size());
  time_ += dt_;
  ++steps_;
  summary_step_ = steps_;
}

template <int Dim>
void Simulation<Dim>::remove_outflow() {
  // Most steps remove nothing: the update's summary holds the front (its largest x) when it is
  // this step's and counted every particle.
  const bool known = summary_step_ == steps_ && summary_.bad < 0;
  if (outflow_.remove(particles_, records_gate() ? &gate_ : nullptr,
                      known ? std::optional<double>(summary_.front) : std::nullopt))
    summary_step_ = -1;  // the update's summary counted the removed particles
}

template <int Dim>
void Simulation<Dim>::inflow() {
  if (settling_.active) return;
  if (inflow_.feed(particles_, scene_.drive_position(time_))) summary_step_ = -1;  // it did not see the new ice
}

template <int Dim>
typename Simulation<Dim>::StepSummary Simulation<Dim>::merge(StepSummary a, const StepSummary& b) {
  a.v2 = std::max(a.v2, b.v2);
  a.front = std::max(a.front, b.front);
  if (a.bad < 0 || (b.bad >= 0 && b.bad < a.bad)) a.bad = b.bad;
  return a;
}

template <int Dim>
[[gnu::always_inline]] inline void Simulation<Dim>::summarise_particle(std::size_t p, StepSummary& a) const {
  const auto& P = particles_;
  const double v2 = P.v[p].squaredNorm();
  if (!std::isfinite(v2) || !P.tau[p].allFinite()) {
    if (a.bad < 0) a.bad = static_cast<std::int64_t>(p);
    return;
  }
  a.v2 = std::max(a.v2, v2);
  a.front = std::max(a.front, P.x[p][0]);
}

template <int Dim>
typename Simulation<Dim>::StepSummary Simulation<Dim>::summarise_particles() const {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, particles_.size(), kGrain), StepSummary{},
      [&](const auto& r, StepSummary a) {
        for (std::size_t p = r.begin(); p != r.end(); ++p) summarise_particle(p, a);
        return a;
      },
      merge);
}

template <int Dim>
void Simulation<Dim>::update_time_step() {
  const auto& P = particles_;
  // The update sweep's summary when it is this step's and no particle has left since.
  const StepSummary acc = summary_step_ == steps_ ? summary_ : summarise_particles();
  summary_step_ = -1;
  const double dx = scene_.dx;
  // Where an error happened (built only on the error paths below; this runs every step).
  // During settling the step count and time restart at 0 afterwards: say so.
  const auto when = [&] {
    return (settling_.active ? "settling (before t = 0), step " : "step ") + std::to_string(steps_) +
           ", t = " + std::to_string(time_);
  };
  // The particle with the largest speed (only on the error paths below).
  const auto fastest = [&] {
    std::size_t worst = 0;
    for (std::size_t p = 0; p < P.size(); ++p)
      if (P.v[p].squaredNorm() >= acc.v2) worst = p;
    return worst;
  };
  if (acc.bad >= 0) {
    const auto p = static_cast<std::size_t>(acc.bad);
    throw SimulationError(when() +
                          " s: particle " + std::to_string(p) + " at " +
                          describe_position(P.x[p].data(), Dim) +
                          " has a non-finite velocity or stress (numerical instability; lower "
                          "numerics.cfl, now " + std::to_string(scene_.cfl) + ")");
  }
  const double vmax = std::sqrt(acc.v2);
  if (steps_ > 0 && vmax * dt_ > dx) {
    // The CFL step bounds |v|·dt by cfl·dx with the velocities of the previous step; a particle
    // that moved more than a whole cell in one step means the update has blown up.
    const std::size_t worst = fastest();
    throw SimulationError(when() + " s: particle " + std::to_string(worst) + " at " +
                          describe_position(P.x[worst].data(), Dim) + " moved " +
                          std::to_string(vmax * dt_) + " m in one step (> dx = " +
                          std::to_string(dx) + " m) at speed " + std::to_string(vmax) +
                          " m/s: the explicit update is unstable (numerics.cfl = " +
                          std::to_string(scene_.cfl) + "; keep it ≤ 1)");
  }
  if (speed_bound_ > 0.0 && vmax > speed_bound_) {
    // A mild instability (CFL just above its limit) grows particle speeds without ever moving a
    // particle a whole cell in one step; bound them by the physics instead (speed_bound_).
    const std::size_t worst = fastest();
    throw SimulationError(when() + " s: particle " + std::to_string(worst) + " at " +
                          describe_position(P.x[worst].data(), Dim) + " has speed " +
                          std::to_string(vmax) + " m/s, above the physical bound " +
                          std::to_string(speed_bound_) +
                          " m/s (1.5 × (2 V_x + sqrt(2 g (H_s + H_i)))): the explicit update is "
                          "unstable (numerics.cfl = " + std::to_string(scene_.cfl) +
                          "; keep it ≤ 1)");
  }
  max_speed_ = vmax;
  front_x_ = P.size() ? acc.front : 0.0;
  dt_ = scene_.cfl * dx / (scene_.p_wave_speed() + vmax);
}

template <int Dim>
void Simulation<Dim>::save_checkpoint(const std::string& path, std::optional<double> wall_s) const {
  const RunCounters run{time_,           dt_,       steps_,           particle_steps_,
                        return_map_evaluations_, outflow_.removed_mass(), front_x_, max_speed_,
                        settling_.done,  inflow_.mass(), inflow_.columns(), wall_s};
  crevasse::save_checkpoint(path, scene_, run, particles_, gate_);
}

template <int Dim>
std::optional<double> Simulation<Dim>::load_checkpoint(const std::string& path) {
  RunCounters r;
  crevasse::load_checkpoint(path, scene_, r, particles_, gate_);
  time_ = r.time; dt_ = r.dt; steps_ = r.steps; particle_steps_ = r.particle_steps;
  return_map_evaluations_ = r.return_map_evaluations; outflow_.set_removed_mass(r.removed_mass); front_x_ = r.front_x;
  max_speed_ = r.max_speed; settling_.done = r.settled; settling_.active = false;
  inflow_.restore(r.inflow_mass, r.inflow_columns);
  return r.wall_s;
}

template class Simulation<2>;
template class Simulation<3>;

}  // namespace crevasse
