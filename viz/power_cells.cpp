#include "viz/power_cells.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_2.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Regular_triangulation_face_base_2.h>
#include <CGAL/Regular_triangulation_vertex_base_2.h>
#include <CGAL/Regular_triangulation_vertex_base_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vb3 =
    CGAL::Triangulation_vertex_base_with_info_3<std::size_t, K,
                                                CGAL::Regular_triangulation_vertex_base_3<K>>;
using Tds3 = CGAL::Triangulation_data_structure_3<Vb3, CGAL::Regular_triangulation_cell_base_3<K>>;
using RT3 = CGAL::Regular_triangulation_3<K, Tds3>;
using Vb2 =
    CGAL::Triangulation_vertex_base_with_info_2<std::size_t, K,
                                                CGAL::Regular_triangulation_vertex_base_2<K>>;
using Tds2 = CGAL::Triangulation_data_structure_2<Vb2, CGAL::Regular_triangulation_face_base_2<K>>;
using RT2 = CGAL::Regular_triangulation_2<K, Tds2>;

/// n . x <= d; `tag`: the grain across it, -1 the boundary
struct HalfSpace {
  Vec3 n;
  double d;
  std::int64_t tag;
};

// The power neighbours of each grain (indices), from the regular triangulation with weights r^2.
std::vector<std::vector<std::size_t>> power_neighbours(const std::vector<Vec3>& p,
                                                       const std::vector<double>& r, int dim) {
  std::vector<std::vector<std::size_t>> nb(p.size());
  if (dim == 3) {
    std::vector<std::pair<RT3::Weighted_point, std::size_t>> in;
    for (std::size_t i = 0; i < p.size(); ++i)
      in.emplace_back(RT3::Weighted_point(K::Point_3(p[i].x(), p[i].y(), p[i].z()), r[i] * r[i]),
                      i);
    RT3 rt(in.begin(), in.end());
    std::vector<RT3::Vertex_handle> adj;
    for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v) {
      adj.clear();
      rt.finite_adjacent_vertices(v, std::back_inserter(adj));
      for (const auto& a : adj)
        nb[v->info()].push_back(a->info());
    }
  } else {
    std::vector<std::pair<RT2::Weighted_point, std::size_t>> in;
    for (std::size_t i = 0; i < p.size(); ++i)
      in.emplace_back(RT2::Weighted_point(K::Point_2(p[i].x(), p[i].y()), r[i] * r[i]), i);
    RT2 rt(in.begin(), in.end());
    for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v) {
      auto c = rt.incident_vertices(v), done = c;
      if (c == nullptr)
        continue;
      do
        if (!rt.is_infinite(c))
          nb[v->info()].push_back(c->info());
      while (++c != done);
    }
  }
  for (auto& n : nb)
    std::sort(n.begin(), n.end()); // a fixed clipping order: results independent of CGAL's
  return nb;
}

// The radical half-space of grain i against grain j: |x - pi|^2 - ri^2 <= |x - pj|^2 - rj^2.
HalfSpace radical(const Vec3& pi, double ri, const Vec3& pj, double rj, std::int64_t j) {
  return {2 * (pj - pi), pj.squaredNorm() - pi.squaredNorm() - rj * rj + ri * ri, j};
}

// The shape's bounding half-spaces (box faces, or the round side's planes and the z/y ends).
std::vector<HalfSpace> shape_planes(const ClipShape& c) {
  std::vector<HalfSpace> h;
  for (int k = 0; k < c.dim; ++k) {
    if (c.round && k < 2)
      continue;
    h.push_back({Vec3::Unit(k), c.hi[k], -1});
    h.push_back({-Vec3::Unit(k), -c.lo[k], -1});
  }
  if (c.round)
    for (int s = 0; s < c.sides; ++s) {
      const double a = 2 * std::numbers::pi * (s + 0.5) / c.sides;
      const Vec3 n(std::cos(a), std::sin(a), 0);
      h.push_back({n, n.dot(c.center) + c.radius, -1}); // the polygon circumscribes the circle
    }
  return h;
}

// --- 2D: a convex polygon with a tag on each edge (edge k runs from v[k] to v[k + 1]) ---------
struct Polygon {
  std::vector<Vec3> v;
  std::vector<std::int64_t> tag;
};

void clip(Polygon& poly, const HalfSpace& h) {
  const double tol = 1e-12 * (std::abs(h.d) + 1e-30);
  Polygon out;
  const std::size_t n = poly.v.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 &a = poly.v[k], &b = poly.v[(k + 1) % n];
    const double da = h.n.dot(a) - h.d, db = h.n.dot(b) - h.d;
    if (da <= tol) {
      out.v.push_back(a), out.tag.push_back(poly.tag[k]);
      if (db > tol)
        out.v.push_back(a + (b - a) * (da / (da - db))), out.tag.push_back(h.tag);
    } else if (db <= tol) {
      out.v.push_back(a + (b - a) * (da / (da - db))), out.tag.push_back(poly.tag[k]);
    }
  }
  poly = std::move(out);
}

PowerCell cell_2d(Polygon poly) {
  PowerCell c;
  const std::size_t n = poly.v.size();
  for (std::size_t k = 0; k < n && n >= 3; ++k) {
    const Vec3 &a = poly.v[k], &b = poly.v[(k + 1) % n];
    c.volume += 0.5 * (a.x() * b.y() - b.x() * a.y());
    if ((b - a).norm() > 0) {
      c.faces.push_back({a, b});
      c.neighbour.push_back(poly.tag[k]);
    }
  }
  c.volume = std::abs(c.volume);
  return c;
}

// --- 3D: a convex polyhedron as planar faces with tags -----------------------------------------
void clip(PowerCell& cell, const HalfSpace& h) {
  const double tol = 1e-12 * (std::abs(h.d) + 1e-30);
  bool cut = false;
  for (const auto& f : cell.faces)
    for (const Vec3& x : f)
      cut = cut || h.n.dot(x) - h.d > tol;
  if (!cut)
    return;
  PowerCell out;
  std::vector<Vec3> cap;
  for (std::size_t k = 0; k < cell.faces.size(); ++k) {
    const auto& f = cell.faces[k];
    std::vector<Vec3> kept;
    for (std::size_t i = 0; i < f.size(); ++i) {
      const Vec3 &a = f[i], &b = f[(i + 1) % f.size()];
      const double da = h.n.dot(a) - h.d, db = h.n.dot(b) - h.d;
      if (da <= tol)
        kept.push_back(a);
      if ((da <= tol) != (db <= tol)) {
        const Vec3 x = a + (b - a) * (da / (da - db));
        kept.push_back(x);
        cap.push_back(x);
      }
    }
    if (kept.size() >= 3) {
      out.faces.push_back(std::move(kept));
      out.neighbour.push_back(cell.neighbour[k]);
    }
  }
  if (cap.size() >= 3) { // the new face, its points in order about its centroid
    Vec3 m = Vec3::Zero();
    for (const Vec3& x : cap)
      m += x / static_cast<double>(cap.size());
    const Vec3 n = h.n.normalized(), u = n.unitOrthogonal(), w = n.cross(u);
    std::sort(cap.begin(), cap.end(), [&](const Vec3& a, const Vec3& b) {
      return std::atan2((a - m).dot(w), (a - m).dot(u)) <
             std::atan2((b - m).dot(w), (b - m).dot(u));
    });
    std::vector<Vec3> face;
    for (const Vec3& x : cap)
      if (face.empty() || (x - face.back()).norm() > 1e-12 * (x.norm() + 1e-30))
        face.push_back(x);
    if (face.size() >= 3 &&
        (face.front() - face.back()).norm() <= 1e-12 * (face.front().norm() + 1e-30))
      face.pop_back();
    if (face.size() >= 3) {
      out.faces.push_back(std::move(face));
      out.neighbour.push_back(h.tag);
    }
  }
  cell = std::move(out);
}

PowerCell box_cell(const Vec3& lo, const Vec3& hi) {
  PowerCell c;
  for (int k = 0; k < 3; ++k)
    for (int side = 0; side < 2; ++side) {
      const int a = (k + 1) % 3, b = (k + 2) % 3;
      std::vector<Vec3> f;
      for (const auto& [sa, sb] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
        Vec3 x;
        x[k] = side ? hi[k] : lo[k];
        x[a] = sa ? hi[a] : lo[a];
        x[b] = sb ? hi[b] : lo[b];
        f.push_back(x);
      }
      c.faces.push_back(f);
      c.neighbour.push_back(-1);
    }
  return c;
}

void finish_3d(PowerCell& c) {
  Vec3 m = Vec3::Zero();
  double n = 0;
  for (const auto& f : c.faces)
    for (const Vec3& x : f)
      m += x, n += 1;
  if (n == 0)
    return;
  m /= n;
  c.volume = 0;
  for (const auto& f : c.faces) { // pyramids from the centroid
    Vec3 area = Vec3::Zero();
    for (std::size_t i = 1; i + 1 < f.size(); ++i)
      area += (f[i] - f[0]).cross(f[i + 1] - f[0]);
    c.volume += std::abs(area.dot(f[0] - m)) / 6;
  }
}

} // namespace

ClipShape ClipShape::around(const std::vector<Vec3>& pos, const std::vector<double>& radius,
                            int dim, bool round) {
  ClipShape c;
  c.dim = dim, c.round = round;
  c.lo = Vec3::Constant(1e300), c.hi = Vec3::Constant(-1e300);
  for (std::size_t i = 0; i < pos.size(); ++i) {
    c.lo = c.lo.cwiseMin(pos[i] - Vec3::Constant(radius[i]));
    c.hi = c.hi.cwiseMax(pos[i] + Vec3::Constant(radius[i]));
  }
  if (dim == 2)
    c.lo.z() = c.hi.z() = 0;
  if (round) {
    c.center = 0.5 * (c.lo + c.hi);
    c.center.z() = 0;
    for (std::size_t i = 0; i < pos.size(); ++i)
      c.radius = std::max(
          c.radius, std::hypot(pos[i].x() - c.center.x(), pos[i].y() - c.center.y()) + radius[i]);
    c.fit_round_box();
  }
  return c;
}

void ClipShape::fit_round_box() {
  const double R = radius / std::cos(std::numbers::pi / sides); // the polygon's corners
  lo.x() = center.x() - R, hi.x() = center.x() + R;
  lo.y() = center.y() - R, hi.y() = center.y() + R;
}

double ClipShape::volume() const {
  const Vec3 e = hi - lo;
  const double depth = dim == 3 ? e.z() : 1.0;
  if (!round)
    return dim == 3 ? e.x() * e.y() * e.z() : e.x() * e.y();
  const double ri = radius; // inradius of the polygon
  return sides * ri * ri * std::tan(std::numbers::pi / sides) * depth;
}

const std::vector<Vec3>* PowerCell::face_with(std::int64_t j) const {
  for (std::size_t k = 0; k < faces.size(); ++k)
    if (neighbour[k] == j)
      return &faces[k];
  return nullptr;
}

double face_area(const std::vector<Vec3>& f) {
  if (f.size() == 2)
    return (f[1] - f[0]).norm();
  Vec3 a = Vec3::Zero();
  for (std::size_t i = 1; i + 1 < f.size(); ++i)
    a += (f[i] - f[0]).cross(f[i + 1] - f[0]);
  return 0.5 * a.norm();
}

PowerDiagram::PowerDiagram(const std::vector<Vec3>& pos, const std::vector<double>& radius,
                           const ClipShape& clip)
    : pos_(pos), radius_(radius), clip_(clip),
      neighbours_(power_neighbours(pos, radius, clip.dim)) {}

std::vector<PowerCell> PowerDiagram::cells(std::size_t first, std::size_t last) const {
  const std::vector<HalfSpace> outline = shape_planes(clip_);
  last = std::min(last, pos_.size());
  std::vector<PowerCell> cells(last > first ? last - first : 0);
#pragma omp parallel for schedule(dynamic, 64)
  for (std::size_t i = first; i < last; ++i) {
    const std::vector<std::size_t>& nb = neighbours_[i];
    if (nb.empty() && pos_.size() > 1)
      continue; // hidden: an empty cell
    if (clip_.dim == 2) {
      Polygon p;
      const Vec3 &lo = clip_.lo, &hi = clip_.hi;
      p.v = {Vec3(lo.x(), lo.y(), 0), Vec3(hi.x(), lo.y(), 0), Vec3(hi.x(), hi.y(), 0),
             Vec3(lo.x(), hi.y(), 0)};
      p.tag = {-1, -1, -1, -1};
      for (const std::size_t j : nb)
        clip(p, radical(pos_[i], radius_[i], pos_[j], radius_[j], static_cast<std::int64_t>(j)));
      for (const HalfSpace& h : outline)
        clip(p, h);
      cells[i - first] = cell_2d(std::move(p));
    } else {
      PowerCell c = box_cell(clip_.lo, clip_.hi);
      for (const std::size_t j : nb)
        clip(c, radical(pos_[i], radius_[i], pos_[j], radius_[j], static_cast<std::int64_t>(j)));
      for (const HalfSpace& h : outline)
        clip(c, h);
      finish_3d(c);
      cells[i - first] = std::move(c);
    }
  }
  return cells;
}

std::vector<PowerCell> power_cells(const std::vector<Vec3>& pos, const std::vector<double>& radius,
                                   const ClipShape& clip_shape) {
  return PowerDiagram(pos, radius, clip_shape).cells(0, pos.size());
}

} // namespace rocklab
