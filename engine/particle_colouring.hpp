#pragma once
// The race-free order of P2G-style scatters: particle indices grouped by x-slab of kSlabCells
// cells. A particle with stencil base b writes nodes b..b+2 along x, so slabs of 4 cells write
// 6 node columns and slabs of one parity never share a node: they run in parallel. The order
// inside a slab is fixed, so sums are deterministic whatever the thread count.
#include <tbb/parallel_for.h>

#include <cstdint>
#include <vector>

#include "engine/grid.hpp"
#include "engine/particles.hpp"

namespace crevasse {

template <int Dim>
class ParticleColouring {
 public:
  static constexpr int kSlabCells = 4;

  // Groups the particles by slab of `grid`'s box (fitted to them). Reads x.
  void build(const Particles<Dim>& P, const Grid<Dim>& grid);
  void clear() {  // no particles
    start_.assign(2, 0);
    order_.clear();
  }

  // fn(p) for every particle: the slabs of one parity in parallel, then the others.
  template <class Fn>
  void for_each(Fn&& fn) const {
    const int slabs = static_cast<int>(start_.size()) - 1;
    for (int colour = 0; colour < 2; ++colour) {
      tbb::parallel_for(0, (slabs + 1 - colour) / 2, [&](int half) {
        const int s = 2 * half + colour;
        for (std::uint32_t q = start_[s]; q < start_[s + 1]; ++q) fn(order_[q]);
      });
    }
  }

 private:
  std::vector<std::uint32_t> order_;  // particle indices, slab by slab
  std::vector<std::uint32_t> start_;  // where each slab begins in order_ (one past the end last)
  std::vector<std::uint32_t> block_offsets_;  // the counting sort's [block][slab] places, reused
};

extern template class ParticleColouring<2>;
extern template class ParticleColouring<3>;

}  // namespace crevasse
