// The in-place reorders of Particles (the sorting step and the outflow removal) against a plain
// copy-based reference, and the step's independence of the thread count: the parallel slab
// counting sort and the coloured scatters sum every grid node in one fixed order, so a run on
// one thread and on two must agree bit for bit (an equality test, no tolerance: any race or
// order change in a sum shows as a differing bit after a few hundred steps).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>
#include <vector>

#include "engine/particles.hpp"
#include "engine/simulation.hpp"
#include "engine/scene.hpp"
#include "tests/engine/scene_builders.hpp"

namespace crevasse {
namespace {

Particles<2> numbered_particles(std::size_t n, bool optional_arrays) {
  Particles<2> P;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = static_cast<double>(i);
    Mat<2> f;
    f << 1.0 + d, 2.0 + d, 3.0 + d, 4.0 + d;
    P.push_back(Vec<2>(d, -d), 10.0 + d, 20.0 + d, f, -f);
    P.v.back() = Vec<2>(0.5 * d, 0.25 * d);
    P.C.back() = 2.0 * f;
  }
  if (optional_arrays) {
    for (std::size_t i = 0; i < n; ++i) {
      P.eps_v_p.push_back(1e-3 * static_cast<double>(i));
      P.drive_x0.push_back(static_cast<double>(i) + 0.5);
      P.x_ref.push_back({static_cast<float>(i), static_cast<float>(2 * i)});
      P.gate_eps.push_back(static_cast<float>(i) * 0.1f);
    }
  }
  return P;
}

// Particle i of `got` must be particle `from[i]` of `ref`, in every array.
void expect_reordered(const Particles<2>& got, const Particles<2>& ref,
                      const std::vector<std::uint32_t>& from) {
  ASSERT_EQ(got.size(), from.size());
  for (std::size_t i = 0; i < from.size(); ++i) {
    const std::size_t j = from[i];
    EXPECT_EQ(got.x[i], ref.x[j]);
    EXPECT_EQ(got.v[i], ref.v[j]);
    EXPECT_EQ(got.C[i], ref.C[j]);
    EXPECT_EQ(got.F_e[i], ref.F_e[j]);
    EXPECT_EQ(got.tau[i], ref.tau[j]);
    EXPECT_EQ(got.mass[i], ref.mass[j]);
    EXPECT_EQ(got.vol0[i], ref.vol0[j]);
    if (ref.has_plastic_state()) {
      EXPECT_EQ(got.eps_v_p[i], ref.eps_v_p[j]);
      EXPECT_EQ(got.drive_x0[i], ref.drive_x0[j]);
      EXPECT_EQ(got.x_ref[i], ref.x_ref[j]);
      EXPECT_EQ(got.gate_eps[i], ref.gate_eps[j]);
    }
  }
}

TEST(ParticlesReorder, PermuteInPlaceMatchesACopy) {
  std::mt19937 rng(7);
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{63},
                        std::size_t{64}, std::size_t{65}, std::size_t{1000}}) {
    for (bool optional : {false, true}) {
      std::vector<std::vector<std::uint32_t>> orders;
      std::vector<std::uint32_t> id(n);
      std::iota(id.begin(), id.end(), 0u);
      orders.push_back(id);                                   // identity
      auto rot = id;
      if (n > 1) std::rotate(rot.begin(), rot.begin() + 1, rot.end());
      orders.push_back(rot);                                  // one cycle through all
      auto rnd = id;
      std::shuffle(rnd.begin(), rnd.end(), rng);
      orders.push_back(rnd);                                  // random cycles
      for (const auto& order : orders) {
        const Particles<2> ref = numbered_particles(n, optional);
        Particles<2> P = ref;
        P.permute(order);
        expect_reordered(P, ref, order);
      }
    }
  }
}

TEST(ParticlesReorder, CompactInPlaceKeepsOrderAndCountsTheMass) {
  std::mt19937 rng(11);
  std::bernoulli_distribution coin(0.3);
  for (bool optional : {false, true}) {
    const Particles<2> ref = numbered_particles(500, optional);
    Particles<2> P = ref;
    std::vector<char> keep(ref.size());
    std::vector<std::uint32_t> kept;
    double removed = 0.0;
    for (std::size_t i = 0; i < keep.size(); ++i) {
      keep[i] = coin(rng);
      if (keep[i]) kept.push_back(static_cast<std::uint32_t>(i));
      else removed += ref.mass[i];
    }
    EXPECT_EQ(P.compact(keep), removed);  // same sum, same order: exactly equal
    expect_reordered(P, ref, kept);
  }
}

// The outflow compacts from the first particle it removes: the kept prefix is not touched, and
// the result is the whole compaction's.
TEST(ParticlesReorder, CompactFromTheFirstRemovedEqualsTheWholeCompaction) {
  std::mt19937 rng(12);
  std::bernoulli_distribution coin(0.3);
  const Particles<2> ref = numbered_particles(500, true);
  std::vector<char> keep(ref.size(), 1);
  std::vector<std::uint32_t> kept;
  double removed = 0.0;
  const std::size_t first = 400;
  for (std::size_t i = 0; i < keep.size(); ++i) {
    if (i >= first) keep[i] = coin(rng);
    if (keep[i]) kept.push_back(static_cast<std::uint32_t>(i));
    else removed += ref.mass[i];
  }
  ASSERT_FALSE(keep[first] && removed == 0.0);
  Particles<2> P = ref;
  EXPECT_EQ(P.compact(keep, first), removed);
  expect_reordered(P, ref, kept);
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// Every array of the step's state equal, bit for bit.
template <int Dim>
void expect_same_state(const Particles<Dim>& a, const Particles<Dim>& b) {
  EXPECT_GT(a.size(), 0u);
  EXPECT_TRUE(same_bits(a.x, b.x));
  EXPECT_TRUE(same_bits(a.v, b.v));
  EXPECT_TRUE(same_bits(a.C, b.C));
  EXPECT_TRUE(same_bits(a.F_e, b.F_e));
  EXPECT_TRUE(same_bits(a.tau, b.tau));
  EXPECT_TRUE(same_bits(a.eps_v_p, b.eps_v_p));
}

template <int Dim>
Particles<Dim> run_with_threads(const SceneConfig& scene, int threads, int steps) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  Simulation<Dim> sim(scene);
  for (int i = 0; i < steps; ++i) sim.step();
  return sim.particles();
}

template <int Dim>
void expect_thread_count_independent(const SceneConfig& scene, int steps) {
  const Particles<Dim> one = run_with_threads<Dim>(scene, 1, steps);
  const Particles<Dim> two = run_with_threads<Dim>(scene, 2, steps);
  expect_same_state(one, two);
  // The run must have broken ice, or the return mapping's branches were never compared.
  EXPECT_GT(std::count_if(one.eps_v_p.begin(), one.eps_v_p.end(), [](double e) { return e > 0.0; }), 0);
}

// A weak glacier (it breaks within the run) with jittered particles, so that no two particles
// share a lattice position and the sort has real work.
SceneConfig jittered_glacier(test::SmallGlacier g, double jitter) {
  SceneConfig s = test::small_glacier_scene(g);
  s.jitter = jitter;
  return test::finish(s);
}

// 2D: 1,500 steps cross 15 sorting steps; 1,200 particles are more than one 1,024-particle
// block, so the slab sort runs in two blocks.
TEST(ThreadCount, TwoDimensionalGlacierIsBitwiseIdenticalOnOneAndTwoThreads) {
  test::SmallGlacier g;
  g.cohesion_ratio = 0.05;
  g.cells_per_thickness = 10.0;
  expect_thread_count_independent<2>(jittered_glacier(g, 0.4), 1500);
}

// The regime study's numerics (studies/scenes/flowing_weight_cell_2d.json: inflow, outflow, the
// relaxed per-cell whole-volume average, whose cell sums are scattered in the coloured order)
// at its 8 m/s and CFL 0.7, jittered, long enough that ice breaks and leaves through the
// outflow: the same bits on one and two threads.
TEST(ThreadCount, RegimeNumericsWithOutflowAreBitwiseIdenticalOnOneAndTwoThreads) {
  nlohmann::json j = test::shipped_scene_json("flowing_weight_cell_2d.json");
  j["drive"]["speed"] = 8.0;
  j["numerics"]["cfl"] = 0.7;
  j["numerics"]["jitter"] = 0.25;
  const SceneConfig scene = scene_from_json(j);
  ASSERT_TRUE(scene.average_per_cell);
  ASSERT_GT(scene.average_relaxation_time, 0.0);
  const auto run = [&](int threads, double& removed) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    Simulation<2> sim(scene);
    for (int i = 0; i < 3000; ++i) sim.step();  // 17 s of flow
    removed = sim.removed_mass();
    return sim.particles();
  };
  double removed_one = 0.0, removed_two = 0.0;
  const Particles<2> one = run(1, removed_one);
  const Particles<2> two = run(2, removed_two);
  expect_same_state(one, two);
  EXPECT_EQ(removed_one, removed_two);
  EXPECT_GT(removed_one, 0.0);  // the outflow removed ice
  EXPECT_GT(std::count_if(one.eps_v_p.begin(), one.eps_v_p.end(), [](double e) { return e > 0.0; }), 0);
}

// The 2D update runs over vectorised blocks of particles (update_particles_2d); one particle at a
// time, through update_particle, it must give the same bits, cracks included (the block hands
// particles outside a yield surface to the return mapping; the rest it computes itself).
// Returns the block-updated particles.
Particles<2> expect_block_update_matches_per_particle(const SceneConfig& scene, int steps) {
  Simulation<2> block(scene), single(scene);
  single.set_per_particle_update(true);
  for (int i = 0; i < steps; ++i) {
    block.step();
    single.step();
  }
  expect_same_state(block.particles(), single.particles());
  return block.particles();
}

TEST(BlockUpdate, TwoDimensionalGlacierGivesTheParticleByParticleBits) {
  test::SmallGlacier g;
  g.cohesion_ratio = 0.05;
  g.cells_per_thickness = 10.0;
  const Particles<2> a = expect_block_update_matches_per_particle(jittered_glacier(g, 0.4), 1500);
  // The run must have broken ice, or the block's hand-over to the return mapping was not tested.
  const auto& e = a.eps_v_p;
  EXPECT_GT(std::count_if(e.begin(), e.end(), [](double v) { return v > 0.0; }), 0);
}

// Without the ΔJ-bar average the block gathers each particle's velocity itself and takes no
// volume scale: the same bits as one particle at a time, cracks included.
TEST(BlockUpdate, GlacierWithoutVolumeAveragingGivesTheParticleByParticleBits) {
  test::SmallGlacier g;
  g.cohesion_ratio = 0.05;
  g.cells_per_thickness = 10.0;
  SceneConfig s = jittered_glacier(g, 0.4);
  s.volumetric_averaging = false;
  const Particles<2> a = expect_block_update_matches_per_particle(test::finish(s), 1500);
  const auto& e = a.eps_v_p;
  EXPECT_GT(std::count_if(e.begin(), e.end(), [](double v) { return v > 0.0; }), 0);
}

// Creeping ice relaxes at every step, inside the yield surfaces too: the block must send every
// particle through the return mapping (admissible_2d), or it keeps trial states that the
// particle-by-particle update relaxes. Creep must also have acted: the mean von Mises stress
// ends below that of the same glacier without creep.
TEST(BlockUpdate, CreepingGlacierGivesTheParticleByParticleBits) {
  test::SmallGlacier g;
  g.cohesion_ratio = 0.05;
  g.cells_per_thickness = 10.0;
  SceneConfig s = test::small_glacier_scene(g);
  s.jitter = 0.4;
  s.volumetric_averaging = false;
  const SceneConfig plain = test::finish(s);
  // A thousand times softer than temperate ice, so that on this small, fast glacier creep and
  // not q_y sets the deviatoric stress (the creep stress scales as A^{-1/3}: a tenth).
  s.creep_rate_factor = 2.4e-21;
  // 1,500 steps: the first 600 or so are the elastic settling, without the return mapping.
  const Particles<2> creeping = expect_block_update_matches_per_particle(test::finish(s), 1500);
  Simulation<2> rigid(plain);
  for (int i = 0; i < 1500; ++i) rigid.step();
  const auto mean_q = [](const Particles<2>& P) {
    double sum = 0.0;
    for (const Mat<2>& t : P.tau) {
      const double half_diff = 0.5 * (t(0, 0) - t(1, 1));
      sum += std::sqrt(3.0 * (half_diff * half_diff + t(0, 1) * t(0, 1)));
    }
    return sum / static_cast<double>(P.size());
  };
  EXPECT_LT(mean_q(creeping), 0.5 * mean_q(rigid.particles()));
}

// The elastic kernel (no plasticity; also the one a plastic scene runs while settling).
TEST(BlockUpdate, ElasticGlacierGivesTheParticleByParticleBits) {
  test::SmallGlacier g;
  g.cells_per_thickness = 10.0;
  SceneConfig s = test::small_glacier_scene(g);
  std::erase(s.effects, Effect::plasticity);
  std::erase(s.effects, Effect::softening);
  s.jitter = 0.4;
  expect_block_update_matches_per_particle(test::finish(s), 600);
}

TEST(ThreadCount, ThreeDimensionalGlacierIsBitwiseIdenticalOnOneAndTwoThreads) {
  test::SmallGlacier g;
  g.dim = 3;
  g.cohesion_ratio = 0.02;
  g.width_ratio = 0.5;
  g.upstream_ratio = 2.0;
  g.downstream_ratio = 2.0;
  expect_thread_count_independent<3>(jittered_glacier(g, 0.3), 400);
}

}  // namespace
}  // namespace crevasse
