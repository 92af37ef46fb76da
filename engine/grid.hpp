#pragma once
// Dense background grid over a box of lattice nodes [lo, lo + n). Node (i, j[, k]) sits at
// (i, j[, k])·dx. The box is re-fitted to the particles every step, so empty air and rock
// cost nothing. Flattening is x-slowest, which keeps an x-slab of nodes contiguous.
#include <array>
#include <cstddef>
#include <vector>

#include "engine/types.hpp"

namespace crevasse {

// One node's sums, together: P2G adds to all three at once, so a node is one place in memory
// (32 bytes in 2D) instead of one in each of three arrays.
template <int Dim>
struct GridNode {
  double mass = 0.0;
  // Σ w m (1 − D) of the particles around: the weight of the ΔJ-bar average (volume_average.hpp).
  double intact_mass = 0.0;
  Vec<Dim> vel = Vec<Dim>::Zero();  // momentum during P2G, velocity after the grid update
};

template <int Dim>
struct Grid {
  double dx = 1.0;
  IVec<Dim> lo = IVec<Dim>::Zero();
  IVec<Dim> n = IVec<Dim>::Zero();
  std::vector<GridNode<Dim>> nodes;
  std::array<std::size_t, Dim> stride{};  // strides(); set with the box by reset()

  std::size_t node_count() const {
    std::size_t c = 1;
    for (int a = 0; a < Dim; ++a) c *= static_cast<std::size_t>(n[a]);
    return c;
  }
  std::size_t flat(const IVec<Dim>& node) const {
    std::size_t f = 0;
    for (int a = 0; a < Dim; ++a) f = f * n[a] + static_cast<std::size_t>(node[a] - lo[a]);
    return f;
  }
  // Flat strides per axis (x slowest: the last axis has stride 1), so that node base + off has
  // the flat index flat(base) + Σ off[a]·stride[a] (the stencil loops of P2G and G2P). Set
  // by reset(), with the box.
  const std::array<std::size_t, Dim>& strides() const { return stride; }
  IVec<Dim> node_of(std::size_t f) const {
    IVec<Dim> node;
    for (int a = Dim - 1; a >= 0; --a) {
      node[a] = lo[a] + static_cast<int>(f % n[a]);
      f /= n[a];
    }
    return node;
  }
  Vec<Dim> position(const IVec<Dim>& node) const { return node.template cast<double>() * dx; }

  void reset(const IVec<Dim>& new_lo, const IVec<Dim>& new_n) {
    lo = new_lo;
    n = new_n;
    stride[Dim - 1] = 1;
    for (int a = Dim - 2; a >= 0; --a) stride[a] = stride[a + 1] * static_cast<std::size_t>(n[a + 1]);
    nodes.assign(node_count(), GridNode<Dim>{});
  }
};

}  // namespace crevasse
