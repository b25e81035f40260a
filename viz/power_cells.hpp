// Faced grains: each grain's cell of the power (Laguerre) diagram of the packing, the weighted
// Voronoi diagram with weight r^2, from CGAL's regular triangulation (2D and 3D), clipped to the
// specimen's shape. Two grains' cells share the face on their radical plane, so a broken contact
// drawn as that face joins its neighbours into continuous fracture surfaces. Units SI (m, m^2,
// m^3; 2D areas are volumes of unit thickness).
#pragma once

#include "core/types.hpp"

#include <cstdint>
#include <vector>

namespace rocklab {

/// The region the cells fill: a box, or (round) a cylinder about z in 3D / a disk in 2D, drawn as
/// a prism / polygon of `sides` sides.
struct ClipShape {
  int dim = 3;
  bool round = false;
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero(); ///< box (round: the z range, and its bounding box)
  Vec3 center = Vec3::Zero();                ///< round: the axis passes through it
  double radius = 0;                         ///< round
  int sides = 96;
  /// The smallest such shape holding every grain (its extent pos +- r): the specimen as it is.
  static ClipShape around(const std::vector<Vec3>& pos, const std::vector<double>& radius, int dim,
                          bool round);
  /// Its volume (2D: area x unit thickness), of the polygon it is drawn as.
  double volume() const;
  /// Round: set the x and y range to the polygon's (about center, inradius radius).
  void fit_round_box();
};

/// One grain's cell: its faces (3D: planar polygons; 2D: the polygon's edges, two points each),
/// the grain across each face (-1: the specimen's boundary) and its volume (2D: area).
struct PowerCell {
  std::vector<std::vector<Vec3>> faces;
  std::vector<std::int64_t> neighbour; ///< index of the grain across each face, -1 boundary
  double volume = 0;
  /// The face shared with grain `j` (empty if the two cells do not touch).
  const std::vector<Vec3>* face_with(std::int64_t j) const;
};

/// The power diagram of a packing: its neighbour lists, from which any grain's clipped cell is
/// built on demand, so that a large packing's cells can be made and written a range at a time
/// (10k grains' cells at once took ~30 MB, their polygon file ~45 MB more).
class PowerDiagram {
public:
  /// Keeps references to pos and radius: they must outlive the diagram.
  PowerDiagram(const std::vector<Vec3>& pos, const std::vector<double>& radius,
               const ClipShape& clip);
  std::size_t size() const { return pos_.size(); }
  /// Every grain's neighbours: the grains whose power cells share a face with its cell (before
  /// clipping), in ascending order.
  const std::vector<std::vector<std::size_t>>& neighbours() const { return neighbours_; }
  /// The clipped cells of grains [first, last), in grain order. A grain whose power cell is
  /// empty (hidden by larger neighbours) gets an empty cell.
  std::vector<PowerCell> cells(std::size_t first, std::size_t last) const;

private:
  const std::vector<Vec3>& pos_;
  const std::vector<double>& radius_;
  ClipShape clip_;
  std::vector<std::vector<std::size_t>> neighbours_;
};

/// The clipped power cells of all grains (same order as pos).
std::vector<PowerCell> power_cells(const std::vector<Vec3>& pos, const std::vector<double>& radius,
                                   const ClipShape& clip);

/// Area of a planar polygon (3D) or length of a segment (2D, two points).
double face_area(const std::vector<Vec3>& face);

} // namespace rocklab
