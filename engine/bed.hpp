#pragma once
// The bedrock as a signed-distance function of (x, z): negative inside the rock, positive in
// the ice/air above. Every shape is a polyline z_b(x) (a vertical step is a vertical segment),
// so a new bed shape is one factory function.
#include <array>
#include <vector>

namespace crevasse {

class Bed {
 public:
  using Point = std::array<double, 2>;  // (x, z)

  // Plateau z = height for x ≤ x_top, straight ramp of horizontal length `length` down to the
  // floor z = 0 (length 0: vertical step), floor to x_end.
  // lip_radius > 0 rounds the convex corner at x_top with a circular arc of that radius, tangent
  // to the plateau and the ramp (the caller keeps the arc's reach on both).
  static Bed step(double x_top, double height, double length, double x_begin, double x_end,
                  double lip_radius = 0.0);
  // Concave (trough-like) ramp: z_b = height·(1 − s)² with s = (x − x_top)/length, steep at the
  // top and flattening into the floor, as over a subglacial cauldron rim.
  static Bed concave(double x_top, double height, double length, double x_begin, double x_end);
  static Bed flat(double z0, double x_begin, double x_end);
  // Any polyline with x non-decreasing, e.g. a snapshot's bed_profile.
  static Bed polyline(std::vector<Point> vertices) { return Bed(std::move(vertices)); }

  double height_at(double x) const;  // z_b(x); the upper value on a vertical segment
  double signed_distance(double x, double z) const;
  // Unit normal of the bed surface nearest to (x, z), pointing out of the rock.
  Point normal(double x, double z) const;
  const std::vector<Point>& vertices() const { return vertices_; }

 private:
  explicit Bed(std::vector<Point> v) : vertices_(std::move(v)) {}
  // Closest point on the polyline to p, and the index of its segment.
  Point closest_point(const Point& p, std::size_t* segment) const;
  std::vector<Point> vertices_;
};

}  // namespace crevasse
