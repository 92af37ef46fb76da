#pragma once
#include <Eigen/Core>
#include <array>

namespace crevasse {

template <int Dim>
using Vec = Eigen::Matrix<double, Dim, 1>;
template <int Dim>
using Mat = Eigen::Matrix<double, Dim, Dim>;
template <int Dim>
using IVec = Eigen::Matrix<int, Dim, 1>;

// Axis of "up" (z): the last coordinate in 2D (x, z) and in 3D (x, y, z).
template <int Dim>
constexpr int up_axis = Dim - 1;

// The first Dim components of a scene file's 3-vector.
template <int Dim>
Vec<Dim> to_vec(const std::array<double, 3>& a) {
  Vec<Dim> v;
  for (int i = 0; i < Dim; ++i) v[i] = a[i];
  return v;
}

}  // namespace crevasse
