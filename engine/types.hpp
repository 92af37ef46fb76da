#pragma once
#include <Eigen/Core>

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

}  // namespace crevasse
