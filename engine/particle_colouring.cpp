#include "engine/particle_colouring.hpp"

#include <algorithm>

#include "engine/fast_math.hpp"

namespace crevasse {

template <int Dim>
void ParticleColouring<Dim>::build(const Particles<Dim>& P, const Grid<Dim>& grid) {
  // Counting sort of particle indices into x-slabs, stable: within a slab the particles keep
  // their index order, so P2G sums in a fixed order and is deterministic whatever the thread
  // count. Parallel over a fixed number of index blocks (not one per thread, so the result
  // never depends on the thread count): each block counts its particles per slab, a prefix
  // over (slab, block) gives each block its place in every slab, and each block then fills
  // its places in index order, which is exactly the serial stable order.
  constexpr std::size_t kGrain = 1024;
  const std::size_t n = P.size();
  const double inv_dx = 1.0 / grid.dx;
  const std::size_t slabs = static_cast<std::size_t>((grid.n[0] + kSlabCells - 1) / kSlabCells);
  const std::size_t blocks = std::min<std::size_t>(64, (n + kGrain - 1) / kGrain);
  const std::size_t block_size = (n + blocks - 1) / blocks;
  const int lo_x = grid.lo[0];
  const auto slab_of = [&](std::size_t p) {
    const int b = floor_to_int(P.x[p][0] * inv_dx - 0.5) - lo_x;
    return static_cast<std::size_t>(b / kSlabCells);
  };
  auto& offsets = block_offsets_;  // [block][slab]
  offsets.assign(blocks * slabs, 0);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t k) {
    std::uint32_t* count = offsets.data() + k * slabs;
    for (std::size_t p = k * block_size, e = std::min(n, p + block_size); p < e; ++p)
      ++count[slab_of(p)];
  });
  start_.assign(slabs + 1, 0);
  std::uint32_t at = 0;
  for (std::size_t s = 0; s < slabs; ++s) {
    start_[s] = at;
    for (std::size_t k = 0; k < blocks; ++k) {
      const std::uint32_t c = offsets[k * slabs + s];
      offsets[k * slabs + s] = at;
      at += c;
    }
  }
  start_[slabs] = at;
  order_.resize(n);
  tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t k) {
    std::uint32_t* place = offsets.data() + k * slabs;
    for (std::size_t p = k * block_size, e = std::min(n, p + block_size); p < e; ++p)
      order_[place[slab_of(p)]++] = static_cast<std::uint32_t>(p);
  });
}

template class ParticleColouring<2>;
template class ParticleColouring<3>;

}  // namespace crevasse
