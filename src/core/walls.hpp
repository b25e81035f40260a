// Walls: rigid collections of facets (segments in 2D, triangles in 3D) with prescribed motion.
#pragma once

#include "core/types.hpp"

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace rocklab {

/// A planar piece of a wall: a segment (nv = 2) in 2D or a triangle (nv = 3) in 3D.
struct Facet {
  std::array<Vec3, 3> v{Vec3::Zero(), Vec3::Zero(), Vec3::Zero()}; ///< vertices [m]
  int nv = 3;
};

/// A wall moves rigidly with a prescribed velocity and spin about its centre of rotation.
/// It is either a set of facets or, when `cylinder_radius` > 0, an exact circular cylinder (3D)
/// or circle (2D) of that radius about `axis` through `center`, reaching `half_height` along the
/// axis on either side (3D; <= 0: unbounded). Balls touch a cylinder from inside or outside.
struct Wall {
  std::string name;
  std::vector<Facet> facets;
  double cylinder_radius = 0;   ///< > 0: an analytic cylinder/circle wall [m]
  double half_height = 0;       ///< axial half length of a cylinder wall [m], <= 0 unbounded
  Vec3 center = Vec3::Zero();   ///< centre of rotation [m]
  Vec3 velocity = Vec3::Zero(); ///< translational velocity [m/s]
  Vec3 spin = Vec3::Zero();     ///< rotational velocity about center [rad/s]
  /// Radial motion: every point moves away from the axis (through `center`, along `axis`) at
  /// this speed, so a cylindrical or circular wall grows or shrinks [m/s].
  double radial_velocity = 0;
  Vec3 axis = Vec3::UnitZ();
  double radial_force = 0;    ///< sum of contact force components along the outward radius [N]
  Vec3 force = Vec3::Zero();  ///< resultant contact force acting on the wall [N]
  Vec3 moment = Vec3::Zero(); ///< resultant contact moment about center [N m]
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero(); ///< bounding box [m]

  void update_bounds();
  /// Advance the wall by one step of length dt (translation, then rotation about center).
  void move(double dt);
  /// Largest distance a vertex moves in one step of length dt [m].
  double max_vertex_speed() const;
  /// The point of the wall closest to p (the first facet wins a tie); `facet` receives its index.
  Vec3 closest_point(const Vec3& p, std::int32_t* facet = nullptr) const;
  bool is_cylinder() const { return cylinder_radius > 0; }
  /// Outward radial unit vector at p (zero on the axis).
  Vec3 radial_dir(const Vec3& p) const {
    Vec3 r = p - center;
    r -= r.dot(axis) * axis;
    const double n = r.norm();
    return n > 0 ? Vec3(r / n) : Vec3::Zero();
  }
};

/// A square plane wall of side `extent` through p with unit normal n, centred on p (3D: two
/// triangles; 2D: a segment in the xy plane; balls touch it from either side). In 3D the square's
/// edges run along `edge` and n x edge; by default `edge` is the x axis projected onto the plane
/// (the y axis when n is near x).
Wall plane_wall(int dim, const std::string& name, const Vec3& p, const Vec3& n, double extent,
                const std::optional<Vec3>& edge = std::nullopt);

/// Closest point of a facet to p.
Vec3 closest_point_on_facet(const Facet& f, const Vec3& p);

} // namespace rocklab
