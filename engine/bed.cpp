#include "engine/bed.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace crevasse {

Bed Bed::step(double x_top, double height, double length, double x_begin, double x_end, double lip_radius) {
  if (!(lip_radius > 0.0)) return Bed({{x_begin, height}, {x_top, height}, {x_top + length, 0.0}, {x_end, 0.0}});
  // The ramp turns down by θ = atan(height/length); the arc's centre lies R below the plateau,
  // t = R tan(θ/2) before the corner, and the arc runs from the plateau's tangent point to the
  // ramp's, (x_top − t, height − R) + R (sin α, cos α) for α in [0, θ].
  const double theta = std::atan2(height, length);
  const double t = lip_radius * std::tan(0.5 * theta);
  const double cx = x_top - t, cz = height - lip_radius;
  std::vector<Point> v{{x_begin, height}};
  constexpr int kSegments = 48;  // chord error R(1 − cos(θ/96)) < 1e-4·R
  for (int i = 0; i <= kSegments; ++i) {
    const double a = theta * i / kSegments;
    v.push_back({cx + lip_radius * std::sin(a), cz + lip_radius * std::cos(a)});
  }
  if (length > 0.0) v.push_back({x_top + length, 0.0});
  else v.push_back({x_top, 0.0});
  v.push_back({x_end, 0.0});
  return Bed(std::move(v));
}

Bed Bed::concave(double x_top, double height, double length, double x_begin, double x_end) {
  std::vector<Point> v{{x_begin, height}};
  constexpr int kSegments = 48;  // chord error < 1e-3·height: well below any grid spacing
  for (int i = 0; i <= kSegments; ++i) {
    const double s = static_cast<double>(i) / kSegments;
    v.push_back({x_top + s * length, height * (1.0 - s) * (1.0 - s)});
  }
  v.push_back({x_end, 0.0});
  return Bed(std::move(v));
}

Bed Bed::flat(double z0, double x_begin, double x_end) { return Bed({{x_begin, z0}, {x_end, z0}}); }

double Bed::height_at(double x) const {
  const auto& v = vertices_;
  if (x <= v.front()[0]) return v.front()[1];
  double best = -std::numeric_limits<double>::infinity();
  bool found = false;
  for (std::size_t i = 0; i + 1 < v.size(); ++i) {
    const double x0 = v[i][0], x1 = v[i + 1][0];
    if (x < x0 || x > x1) continue;
    const double z = (x1 > x0) ? v[i][1] + (v[i + 1][1] - v[i][1]) * (x - x0) / (x1 - x0)
                               : std::max(v[i][1], v[i + 1][1]);
    best = std::max(best, z);
    found = true;
  }
  return found ? best : v.back()[1];
}

Bed::Point Bed::closest_point(const Point& p, std::size_t* segment) const {
  double best = std::numeric_limits<double>::infinity();
  Point best_q{};
  for (std::size_t i = 0; i + 1 < vertices_.size(); ++i) {
    const Point& a = vertices_[i];
    const Point& b = vertices_[i + 1];
    const double ex = b[0] - a[0], ez = b[1] - a[1];
    const double len2 = ex * ex + ez * ez;
    double t = len2 > 0 ? ((p[0] - a[0]) * ex + (p[1] - a[1]) * ez) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const Point q{a[0] + t * ex, a[1] + t * ez};
    const double d2 = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]);
    if (d2 < best) {
      best = d2;
      best_q = q;
      if (segment) *segment = i;
    }
  }
  return best_q;
}

double Bed::signed_distance(double x, double z) const {
  const Point q = closest_point({x, z}, nullptr);
  const double d = std::hypot(x - q[0], z - q[1]);
  return z < height_at(x) ? -d : d;
}

Bed::Point Bed::normal(double x, double z) const {
  std::size_t seg = 0;
  const Point q = closest_point({x, z}, &seg);
  double nx = x - q[0], nz = z - q[1];
  const double d = std::hypot(nx, nz);
  if (d > 1e-9) {
    const double sign = z < height_at(x) ? -1.0 : 1.0;
    return {sign * nx / d, sign * nz / d};
  }
  // On the surface: the segment's left normal (polyline runs in +x, rock below).
  const Point& a = vertices_[seg];
  const Point& b = vertices_[seg + 1];
  const double ex = b[0] - a[0], ez = b[1] - a[1];
  const double len = std::hypot(ex, ez);
  return {-ez / len, ex / len};
}

}  // namespace crevasse
