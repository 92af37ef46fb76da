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

namespace crevasse {
namespace {

// P2G colouring: a particle with stencil base b writes nodes b..b+2 along x. Slabs of 4 cells
// write 6 node columns, so slabs of one parity never share a node and run in parallel.
constexpr int kSlabCells = 4;
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
  grid_.dx = scene_.dx;
  domain_lo_ = to_vec<Dim>(scene_.domain_min);
  domain_hi_ = to_vec<Dim>(scene_.domain_max);

  const double x_lo = scene_.domain_min[0], x_hi = scene_.domain_max[0];
  if (scene_.bed_shape == BedShape::step) {
    bed_ = Bed::step(scene_.step_top_x(), scene_.step_height, scene_.step_length, x_lo, x_hi);
  } else if (scene_.bed_shape == BedShape::concave) {
    bed_ = Bed::concave(scene_.step_top_x(), scene_.step_height, scene_.step_length, x_lo, x_hi);
  } else if (scene_.bed_shape == BedShape::flat) {
    bed_ = Bed::flat(scene_.flat_bed_z, x_lo, x_hi);
  }
  if (bed_) bed_field_ = BedField<Dim>(*bed_, domain_lo_, domain_hi_, scene_.dx);
  particles_ = seed_ice<Dim>(scene_, moduli_, bed_ ? &*bed_ : nullptr);
  if (scene_.records_gate()) gate_ = GateRecorder<Dim>(particles_, scene_.gate_x());
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
    // The nodes up to kInflowHoldCells from the back move at V(t) along x, free vertically.
    // Every particle within 2.5 cells of the back has its whole stencil on them, so it moves at
    // exactly V(t) and its F_E sees the same velocity field as its position does; the ice ahead
    // is pushed through the grid, and its compression is stress.
    add_stage("inflow_grid", [this] {
      hold_nodes_at_speed(grid_, -kInfinity, kInflowHoldCells * scene_.dx, drive_speed_now(), false);
    });
  }
  // The boundary stages between these two brackets are the only ones that can act on the
  // downstream band (bed friction and gravity come before); their change of its momentum is the
  // impulse the domain's end gives the ice. The band is a contiguous tail of the nodes (x is
  // the slowest axis), a few columns: negligible next to the step.
  const bool glacier = scene_.body == Body::slab;
  if (glacier)
    add_stage("downstream_band_before", [this] { downstream_before_z_ = downstream_band_momentum_z(); });
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
      if (!settling_) downstream_impulse_z_ += downstream_band_momentum_z() - downstream_before_z_;
    });
  if (scene_.settle_time > 0.0) {
    // Damping exists only while settling: one branch per step, none per particle.
    settle_damping_rate_ = scene_.p_wave_speed() /
                           (scene_.body == Body::slab ? scene_.ice_thickness
                                                  : scene_.box_max[Dim - 1] - scene_.box_min[Dim - 1]);
    add_stage("settle_damping", [this] {
      if (!settling_) return;
      const double f = std::exp(-settle_damping_rate_ * dt_);
      for (auto& g : grid_.nodes) g.vel *= f;
    });
  }
  const bool plastic = scene_.has(Effect::plasticity);
  // The particle update: with the average, after a sweep that gathers the velocities and
  // scatters the volume change; without, the gather is fused into it.
  const bool average = scene_.volumetric_averaging;
  if (average) {
    add_stage("g2p_velocity", [this] { gather_velocities_and_scatter_volume(); });
    add_stage("volume_averaging", [this] { normalise_volume_average(); });
    if (scene_.average_per_cell) add_stage("cell_average", [this] { average_over_cells(); });
  }
  if (plastic) {
    // No return mapping while settling: the settled state is elastic by construction.
    add_stage("g2p_return_mapping", [this, average] {
      if (average) settling_ ? update_particles<false, true>() : update_particles<true, true>();
      else settling_ ? update_particles<false, false>() : update_particles<true, false>();
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
  if (settled_) return true;
  if (scene_.settle_time <= 0.0) {
    settled_ = true;
    return true;
  }
  // settled_ stays false until the phase ends, so that a checkpoint written while settling
  // (between steps, through keep_going) resumes the phase where it stood.
  settling_ = true;
  while (time_ < scene_.settle_time) {
    step();
    if (keep_going && !keep_going()) {
      settling_ = false;
      return false;
    }
  }
  settling_ = false;
  settled_ = true;
  for (std::size_t p = 0; p < particles_.size(); ++p) {
    particles_.v[p].setZero();
    particles_.C[p].setZero();
  }
  if (scene_.drive_start == DriveStart::moving) start_moving();
  time_ = 0.0;
  steps_ = 0;
  particle_steps_ = 0;
  return_map_evaluations_ = 0;
  for (auto& st : stages_) st = {st.name, 0, 0.0};
  update_time_step();
  return true;
}

template <int Dim>
void Simulation<Dim>::start_moving() {
  // The settled glacier is set sliding as a rigid body at V_x, the speed the drives hold from
  // t = 0: a rigid translation carries no stress, so the start sends no wave through the ice,
  // however long it is. Ice over the ramp then settles onto its bed under gravity; a start with
  // each column already following the bed (v_z = V_x z_b'(x)) has a jump of v_z at the lip and
  // the foot, and cracked both at once (twice the damaged particles after 1 s at H_i = 200 m).
  for (std::size_t p = 0; p < particles_.size(); ++p) particles_.v[p][0] = scene_.drive_speed;
}

template <int Dim>
void Simulation<Dim>::step() {
  if (!settled_ && !settling_) settle();
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
    slab_start_.assign(2, 0);
    slab_order_.clear();
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

  // Counting sort of particle indices into x-slabs, stable: within a slab the particles keep
  // their index order, so P2G sums in a fixed order and is deterministic whatever the thread
  // count. Parallel over a fixed number of index blocks (not one per thread, so the result
  // never depends on the thread count): each block counts its particles per slab, a prefix
  // over (slab, block) gives each block its place in every slab, and each block then fills
  // its places in index order, which is exactly the serial stable order.
  const std::size_t slabs = static_cast<std::size_t>((grid_.n[0] + kSlabCells - 1) / kSlabCells);
  const std::size_t blocks = std::min<std::size_t>(64, (n + kGrain - 1) / kGrain);
  const std::size_t block_size = (n + blocks - 1) / blocks;
  const int lo_x = grid_.lo[0];
  const auto slab_of = [&](std::size_t p) {
    const int b = floor_to_int(P.x[p][0] * inv_dx - 0.5) - lo_x;
    return static_cast<std::size_t>(b / kSlabCells);
  };
  auto& offsets = slab_block_offsets_;  // [block][slab]
  offsets.assign(blocks * slabs, 0);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t k) {
    std::uint32_t* count = offsets.data() + k * slabs;
    for (std::size_t p = k * block_size, e = std::min(n, p + block_size); p < e; ++p) ++count[slab_of(p)];
  });
  slab_start_.assign(slabs + 1, 0);
  std::uint32_t at = 0;
  for (std::size_t s = 0; s < slabs; ++s) {
    slab_start_[s] = at;
    for (std::size_t k = 0; k < blocks; ++k) {
      const std::uint32_t c = offsets[k * slabs + s];
      offsets[k * slabs + s] = at;
      at += c;
    }
  }
  slab_start_[slabs] = at;
  slab_order_.resize(n);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t k) {
    std::uint32_t* place = offsets.data() + k * slabs;
    for (std::size_t p = k * block_size, e = std::min(n, p + block_size); p < e; ++p)
      slab_order_[place[slab_of(p)]++] = static_cast<std::uint32_t>(p);
  });
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
  // the average (gather_velocities_and_scatter_volume), and keeps its e^{−ζ ε_v^p} for the
  // sweeps after (ε_v^p does not change before the update).
  const bool plastic = Average && !P.eps_v_p.empty();
  const bool damage = Average && averaging_weights_damage();
  softening_.resize(plastic ? P.size() : 0);
  const std::array<std::size_t, Dim> stride = grid_.strides();
  GridNode<Dim>* const nodes = grid_.nodes.data();
  for_each_particle_coloured([&](std::uint32_t p) __attribute__((always_inline)) {
    const Vec<Dim> xg = P.x[p] * inv_dx;
    const StencilWeights<Dim> w(xg);
    const double m = P.mass[p];
    // MLS-MPM (Hu et al. 2018): stress enters as an affine momentum term,
    // −dt·V0·τ·D⁻¹ with D⁻¹ = 4/dx² for quadratic B-splines.
    const Mat<Dim> affine = m * P.C[p] - (dt * d_inv * P.vol0[p]) * P.tau[p];
    const Vec<Dim> mv = m * P.v[p];
    double wm = 0.0;
    if constexpr (Average) {
      const double f = plastic ? softening_factor(plastic_, P.eps_v_p[p]) : 1.0;
      if (plastic) softening_[p] = f;
      wm = averaging_weight(p, damage);
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
template <class Fn>
void Simulation<Dim>::for_each_particle_coloured(Fn&& fn) {
  // Race-free scatter: slabs of one parity share no grid node, so they run in parallel; the
  // order inside a slab is fixed, so sums are deterministic whatever the thread count.
  const int slabs = static_cast<int>(slab_start_.size()) - 1;
  for (int colour = 0; colour < 2; ++colour) {
    tbb::parallel_for(0, (slabs + 1 - colour) / 2, [&](int half) {
      const int s = 2 * half + colour;
      for (std::uint32_t q = slab_start_[s]; q < slab_start_[s + 1]; ++q) fn(slab_order_[q]);
    });
  }
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
[[gnu::always_inline]] inline void Simulation<Dim>::gather_velocity(std::size_t p, const StencilWeights<Dim>& w,
                                                                    const StencilOffsets<Dim>& d, std::size_t f0,
                                                                    double c_scale) {
  // APIC/MLS gather of the particle velocity and its affine matrix C = c_scale·B (c_scale =
  // 4/dx², formed once by the caller) from the grid (gather_apic); f0 = flat index of the
  // stencil's base node.
  const GridNode<Dim>* const nodes = grid_.nodes.data();
  Vec<Dim> v;
  Mat<Dim> b;
  gather_apic<Dim>(w, d, f0, grid_.strides(),
                   [nodes](std::size_t f) -> const Vec<Dim>& { return nodes[f].vel; }, v, b);
  particles_.v[p] = v;
  particles_.C[p] = c_scale * b;
}

// ΔJ-bar (cf. the F-bar family, e.g. Coombs et al. 2018, CMAME 333:1–21): the step's volume
// ratio ΔJ_p = det(I + Δt C_p) is mass-averaged onto the grid nodes with the same quadratic
// weights as P2G and interpolated back; each particle then takes the averaged ΔJ̄_p and keeps
// its own isochoric part. A field that varies linearly over the stencil is reproduced, so a
// smooth deformation is unchanged; a particle-to-particle checkerboard is removed.
// Only intact ice is averaged: each particle enters with weight (1 − D) (D the damage,
// 1 − e^{−ζ ε_v^p}) and takes ΔJ_used = (1 − D)·ΔJ̄ + D·ΔJ_p. An opening crack then keeps its
// volume change to itself instead of handing part of it to the intact ice around it, which
// would widen every crack by a cell each time it opens further.
// Three passes, fused with G2P: (1) one coloured sweep gathers v and C and scatters
// (1 − D) m ΔJ and (1 − D) m with the same weights; (2) per node, the average; (3) the update
// sweep interpolates ΔJ̄ back, recomputing ΔJ_p from C (unchanged since (1)). The softening
// factor e^{−ζ ε_v^p} (= 1 − D) is kept per particle from (1) to (3), where the return mapping
// uses it for its cap check and shear strength: a particle that stays off the cap evaluates one
// exponential per step instead of three, and none while intact (e^{−ζ·0} = 1 is not evaluated).
template <int Dim>
bool Simulation<Dim>::averaging_weights_damage() const {
  // Broken ice is left out of the average only once it can break: not while settling, not
  // without softening.
  return particles_.has_plastic_state() && plastic_.softening_zeta > 0.0 && !settling_;
}

template <int Dim>
void Simulation<Dim>::gather_velocities_and_scatter_volume() {
  auto& P = particles_;
  const double dx = scene_.dx, inv_dx = 1.0 / dx, c_scale = 4.0 * inv_dx * inv_dx;
  const bool damage = averaging_weights_damage();
  const bool per_cell = scene_.average_per_cell;
  grid_aux_.assign(2 * grid_.node_count(), 0.0);  // per node Σ w m (1−D) ΔJ (and ΔJ J_E), then (ΔJ̄, has one)
  double* const aux = grid_aux_.data();
  const bool relax = per_cell && scene_.average_relaxation_time > 0.0;
  grid_total_.resize(relax ? grid_.node_count() : 0);  // written by normalise_volume_average
  const std::array<std::size_t, Dim> stride = grid_.strides();
  for_each_particle_coloured([&](std::uint32_t p) __attribute__((always_inline)) {
    const Vec<Dim> xg = P.x[p] * inv_dx;
    const StencilWeights<Dim> w(xg);
    const std::size_t f0 = grid_.flat(w.base());
    gather_velocity(p, w, StencilOffsets<Dim>(w, xg, dx), f0, c_scale);
    const double dj = per_cell ? step_volume_ratio(p) : averaged_volume_ratio(p);
    const double wm = averaging_weight(p, damage);  // the weight P2G added to intact_mass
    if (relax) {
      // The whole volume's sum goes in each node's second slot, free until the normalisation.
      const double jt = dj * P.F_e[p].determinant();
      for_each_stencil_node<Dim>(w, f0, stride, [&](const IVec<Dim>&, std::size_t f, double wt) {
        aux[2 * f] += wt * wm * dj;
        aux[2 * f + 1] += wt * wm * jt;
      });
      return;
    }
    for_each_stencil_node<Dim>(w, f0, stride,
                               [&](const IVec<Dim>&, std::size_t f, double wt) { aux[2 * f] += wt * wm * dj; });
  });
}

template <int Dim>
void Simulation<Dim>::normalise_volume_average() {
  // Per node, once: the averaged ΔJ and whether the node carries one (nodes reached only by
  // (nearly) broken ice do not).
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid_.node_count(), kGrain), [&](const auto& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f) {
      const double intact = grid_.nodes[f].intact_mass;
      const bool has = intact > 1e-9 * grid_.nodes[f].mass;
      if (!grid_total_.empty()) grid_total_[f] = has ? grid_aux_[2 * f + 1] / intact : 0.0;
      grid_aux_[2 * f] = has ? grid_aux_[2 * f] / intact : 0.0;
      grid_aux_[2 * f + 1] = has ? 1.0 : 0.0;
    }
  });
}

template <int Dim>
void Simulation<Dim>::average_over_cells() {
  // numerics.average_per_cell: each particle's trial elastic volume ratio, its own elastic
  // volume times the stencil-averaged step ratio, is averaged over the particles of its grid
  // cell (weights as in the nodal average); the update gives it the cell's mean.
  auto& P = particles_;
  const double inv_dx = 1.0 / scene_.dx;
  const bool damage = averaging_weights_damage();
  cell_aux_.assign(2 * grid_.node_count(), 0.0);
  double* const aux = cell_aux_.data();
  for_each_particle_coloured([&](std::uint32_t p) __attribute__((always_inline)) {
    const Vec<Dim> xg = P.x[p] * inv_dx;
    const StencilWeights<Dim> w(xg);
    const Vec<2> sums = stencil_sums(w);
    const double dj = step_volume_ratio(p);
    const double share = damage ? softening_[p] : 1.0;
    const double total = volume_scale_of(sums[0], sums[1], dj, share) * dj * P.F_e[p].determinant();
    const double wm = averaging_weight(p, damage);
    const std::size_t c = grid_.flat(cell_of(xg));
    aux[2 * c] += wm * total;
    aux[2 * c + 1] += wm;
  });
  // The nodes' ΔJ̄ has served; with the relaxation, their whole-volume average takes its slot,
  // beside the flag the update needs with it.
  const bool relax = !grid_total_.empty();
  double* const nodal = grid_aux_.data();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, grid_.node_count(), kGrain), [&](const auto& r) {
    for (std::size_t f = r.begin(); f != r.end(); ++f) {
      const bool has = aux[2 * f + 1] > 0.0;
      aux[2 * f] = has ? aux[2 * f] / aux[2 * f + 1] : 0.0;
      aux[2 * f + 1] = has ? 1.0 : 0.0;
      if (relax) nodal[2 * f] = grid_total_[f];
    }
  });
}

template <int Dim>
[[gnu::always_inline]] inline Vec<2> Simulation<Dim>::stencil_sums(const StencilWeights<Dim>& w) const {
  // (Σ w·first, Σ w·flag) over the stencil from grid_aux_'s pairs (each node's two slots
  // adjacent: one vector load per node).
  const double* const aux = grid_aux_.data();
  Vec<2> sums = Vec<2>::Zero();
  for_each_stencil_node<Dim>(w, grid_.flat(w.base()), grid_.strides(),
                             [&](const IVec<Dim>&, std::size_t f, double wt) {
    sums += wt * Eigen::Map<const Vec<2>>(aux + 2 * f);
  });
  return sums;
}

template <int Dim>
[[gnu::always_inline]] inline typename Simulation<Dim>::VolumeSums Simulation<Dim>::volume_sums(
    std::size_t p, const StencilWeights<Dim>& w) const {
  // The stencil's Σ w ΔJ̄ and Σ w, or with numerics.average_per_cell the cell's mean and
  // whether it has one, and ΔJ_p of particle p (before its update moves it).
  VolumeSums v{0.0, 0.0, 0.0};
  v.dj = averaged_volume_ratio(p);
  if (scene_.average_per_cell) {
    const std::size_t c = grid_.flat(cell_of(particles_.x[p] / scene_.dx));
    v.jbar = cell_aux_[2 * c];
    v.wsum = cell_aux_[2 * c + 1];
    if (!grid_total_.empty()) {
      // Relaxed towards the stencil's whole-volume average at the rate 1/τ (a particle whose
      // stencil carries none, towards its own).
      const Vec<2> st = stencil_sums(w);  // grid_aux_ holds (T̄, has one) now
      const double target = st[1] > 0.0 ? st[0] / st[1] : v.dj;
      const double a = std::min(1.0, dt_ / scene_.average_relaxation_time);
      v.jbar = (1.0 - a) * v.jbar + a * target;
    }
    return v;
  }
  const Vec<2> sums = stencil_sums(w);
  v.jbar = sums[0];
  v.wsum = sums[1];
  return v;
}

template <int Dim>
ParticleEffects<Dim> Simulation<Dim>::particle_effects_now() const {
  ParticleEffects<Dim> e = effects_;
  if (e.piston && !settling_) {
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
  const bool kept_softening = !softening_.empty();  // P2G kept e^{−ζ ε_v^p} (averaged, plastic)
  const ParticleEffects<Dim> effects = particle_effects_now();
  plastic_.creep_increment = dt_ * creep_rate_;
  // What the update needs of particle p first: with the average, its stencil's sums (its velocity
  // was gathered by gather_velocities_and_scatter_volume); without, the gather itself.
  const auto inputs = [&](std::size_t p, double& jbar, double& wsum, double& dj,
                          double& soft) __attribute__((always_inline)) {
    const Vec<Dim> xg = P.x[p] * inv_dx;
    const StencilWeights<Dim> w(xg);
    if constexpr (Average) {
      const VolumeSums v = volume_sums(p, w);
      jbar = v.jbar;
      wsum = v.wsum;
      dj = v.dj;
      soft = kept_softening ? softening_[p] : 1.0;
    } else {
      gather_velocity(p, w, StencilOffsets<Dim>(w, xg, dx), grid_.flat(w.base()), c_scale);
      soft = Plastic ? softening_factor(plastic_, P.eps_v_p[p]) : 1.0;
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
double Simulation<Dim>::downstream_band_momentum_z() const {
  const double x0 = domain_hi_[0] - (kDownstreamDriveCells + 1.0) * scene_.dx;
  const long first_column = static_cast<long>(std::ceil(x0 / grid_.dx)) - grid_.lo[0];
  if (first_column >= grid_.n[0]) return 0.0;
  double pz = 0.0;
  for (std::size_t f = static_cast<std::size_t>(std::max(0L, first_column)) * grid_.stride[0];
       f < grid_.nodes.size(); ++f)
    pz += grid_.nodes[f].mass * grid_.nodes[f].vel[up_axis<Dim>];
  return pz;
}

template <int Dim>
void Simulation<Dim>::remove_outflow() {
  // Ice within three cells of the downstream end has left the scene (docs/model.md).
  const double x_out = domain_hi_[0] - 3.0 * scene_.dx;
  auto& P = particles_;
  // Most steps remove nothing. The update's summary holds the front (its largest x), so those
  // steps cost nothing; otherwise find the first particle past the line. The particles are
  // sorted with x slowest, so those past it sit near the end and everything before the first
  // stays where it is.
  if (summary_step_ == steps_ && summary_.bad < 0 && summary_.front < x_out) return;
  const std::size_t n = P.size();
  const std::size_t first = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, kGrain), n,
      [&](const auto& r, std::size_t found) {
        for (std::size_t p = r.begin(); p != r.end() && p < found; ++p)
          if (!(P.x[p][0] < x_out)) found = p;
        return found;
      },
      [](std::size_t a, std::size_t b) { return std::min(a, b); });
  if (first == n) return;
  std::vector<char> keep(n, 1);
  for (std::size_t p = first; p < n; ++p) keep[p] = P.x[p][0] < x_out;
  if (records_gate()) gate_.archive_removed(P, keep, first);
  removed_mass_ += P.compact(keep, first);
  summary_step_ = -1;  // the update's summary counted the removed particles
}

template <int Dim>
void Simulation<Dim>::inflow() {
  // The ice within 2.5 cells of the back moves at exactly the drive speed (drive_inflow_nodes).
  // Each time the drive has moved by one particle spacing h, the band of ice h wide that entered
  // last, now at x ∈ [h, 2h), is copied h further back, into the place it has left: the same
  // F_E, stress, mass, velocity and height, so the ice enters settled and loaded, with no step in
  // its state. Serial, once every h/V_x of simulated time.
  if (settling_) return;
  auto& P = particles_;
  const double h = scene_.dx / scene_.particles_per_cell_axis;
  const double s = scene_.drive_position(time_);
  const auto due = static_cast<std::int64_t>(std::floor(s / h));  // columns entered by now
  for (; inflow_columns_ < due; ++inflow_columns_) {
    // The band's place when the drive had moved k h, plus what it has moved since.
    const double since = s - static_cast<double>(inflow_columns_ + 1) * h;
    const double lo = h + since, hi = 2.0 * h + since;
    const std::size_t n = P.size();
    for (std::size_t q = 0; q < n; ++q) {
      if (!(P.x[q][0] >= lo && P.x[q][0] < hi)) continue;
      Vec<Dim> pos = P.x[q];
      pos[0] -= h;
      P.push_back(pos, P.mass[q], P.vol0[q], P.F_e[q], P.tau[q]);
      P.v.back() = P.v[q];
      P.C.back() = P.C[q];
      if (P.has_plastic_state()) P.eps_v_p.push_back(0.0);
      if (records_gate()) GateRecorder<Dim>::add_entering(P, pos, s);
      inflow_mass_ += P.mass[q];
    }
    summary_step_ = -1;  // the update's summary did not see the new ice
  }
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
    return (settling_ ? "settling (before t = 0), step " : "step ") + std::to_string(steps_) +
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
  const RunCounters run{time_,         dt_,     steps_,    particle_steps_, return_map_evaluations_,
                        removed_mass_, front_x_, max_speed_, settled_,       inflow_mass_,
                        inflow_columns_, wall_s};
  crevasse::save_checkpoint(path, scene_, run, particles_, gate_);
}

template <int Dim>
std::optional<double> Simulation<Dim>::load_checkpoint(const std::string& path) {
  RunCounters r;
  crevasse::load_checkpoint(path, scene_, r, particles_, gate_);
  time_ = r.time; dt_ = r.dt; steps_ = r.steps; particle_steps_ = r.particle_steps;
  return_map_evaluations_ = r.return_map_evaluations; removed_mass_ = r.removed_mass; front_x_ = r.front_x;
  max_speed_ = r.max_speed; settled_ = r.settled; settling_ = false;
  inflow_mass_ = r.inflow_mass; inflow_columns_ = r.inflow_columns;
  return r.wall_s;
}

template class Simulation<2>;
template class Simulation<3>;

}  // namespace crevasse
