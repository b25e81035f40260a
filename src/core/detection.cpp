// Contact detection: a cell grid gives the candidate pairs, which are merged with the existing
// contacts in key order (new contacts get their model from the first matching rule).
#include "core/model.hpp"

#include "core/geometry.hpp"
#include "core/parallel.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <functional>
#include <limits>
#include <omp.h>

namespace rocklab {

using namespace detail;

namespace {

bool rule_matches_balls(const ModelRule& r, int ga, int gb) {
  if (r.ball_facet)
    return false;
  auto m = [](int want, int g) { return want < 0 || want == g; };
  return (m(r.group1, ga) && m(r.group2, gb)) || (m(r.group1, gb) && m(r.group2, ga));
}

bool rule_matches_facet(const ModelRule& r, int g, int wall) {
  if (!r.ball_facet)
    return false;
  return (r.group1 < 0 || r.group1 == g) && (r.wall == -1 || r.wall == wall);
}

} // namespace

bool Model::needs_detection() const {
  return 2.0 * max_ball_disp_ + wall_disp_ >= margin_;
}

/// The cell grid of one detection: cells at least one interaction range wide, so only
/// neighbouring cells can hold a pair.
struct detail::CellGrid {
  int dim = 3;
  Vec3 lo = Vec3::Zero();
  double cell = 0;
  std::array<std::int64_t, 3> nc{1, 1, 1};

  std::int64_t of(const Vec3& x, int axis) const {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>((x[axis] - lo[axis]) / cell), 0,
                                    nc[axis] - 1);
  }
  std::size_t index(std::int64_t cx, std::int64_t cy, std::int64_t cz) const {
    return static_cast<std::size_t>((cz * nc[1] + cy) * nc[0] + cx);
  }
  std::size_t index_of(const Vec3& x) const {
    return index(of(x, 0), of(x, 1), dim == 3 ? of(x, 2) : 0);
  }
  std::size_t cells() const { return static_cast<std::size_t>(nc[0] * nc[1] * nc[2]); }
};

void Model::detect() {
  // Editing calls (set_margin, ...) may detect before any cycle, e.g. on a model just read from a
  // file, whose per-thread buffers do not exist yet.
  ensure_thread_buffers();
  candidate_keys_.clear();
  if (balls.size() > 0) {
    const CellGrid grid = bin_balls();
    gather_candidates(grid);
  }
  merge_candidates();
  rebuild_adjacency();
  for (auto& d : balls.disp)
    d.setZero();
  max_ball_disp_ = 0;
  wall_disp_ = 0;
}

detail::CellGrid Model::bin_balls() {
  const std::size_t n = balls.size();
  CellGrid g;
  g.dim = settings.dim;
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max());
  Vec3 hi = -lo;
  double rmax = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lo = lo.cwiseMin(balls.pos[i]);
    hi = hi.cwiseMax(balls.pos[i]);
    rmax = std::max(rmax, balls.radius[i]);
  }
  g.lo = lo;
  g.cell = std::max(2.0 * rmax + margin_, 1e-300);
  // Counted in double: a ball far from the others (1e30 m) must widen the cells, not overflow the
  // integer cell counts.
  const double max_cells = static_cast<double>(std::max<std::size_t>(8 * n, 64));
  if (n > 0 && !std::isfinite((hi - lo).maxCoeff()))
    throw PhysicsError("the balls span more than a double can hold (over 1.8e308 m)");
  for (;; g.cell *= 1.25) { // (a few hundred rounds at most, even for 1e300 m)
    double count = 1, per_axis[3] = {1, 1, 1};
    for (int d = 0; d < g.dim; ++d)
      count *= per_axis[d] = std::floor((hi[d] - lo[d]) / g.cell) + 1;
    if (count <= max_cells) { // then each axis count fits an int64 exactly
      for (int d = 0; d < g.dim; ++d)
        g.nc[d] = static_cast<std::int64_t>(per_axis[d]);
      break;
    }
  }
  // Counting sort of the balls by cell.
  const std::size_t ncells = g.cells();
  cell_start_.assign(ncells + 1, 0);
  cell_items_.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    ++cell_start_[g.index_of(balls.pos[i]) + 1];
  for (std::size_t c = 0; c < ncells; ++c)
    cell_start_[c + 1] += cell_start_[c];
  std::vector<std::int32_t>& fill = adj_items_; // reuse as a cursor buffer
  fill.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i)
    cell_items_[static_cast<std::size_t>(fill[g.index_of(balls.pos[i])]++)] =
        static_cast<std::int32_t>(i);
  return g;
}

void Model::gather_candidates(const CellGrid& g) {
  const std::size_t n = balls.size();
  const int dim = settings.dim;
  for (auto& k : thread_keys_)
    k.clear();
#pragma omp parallel if (n >= kParallelMin)
  {
    const std::size_t tid = static_cast<std::size_t>(omp_get_thread_num());
    std::vector<std::uint64_t>& keys = thread_keys_[tid];
    keys.clear();
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3& xi = balls.pos[i];
      const double ri = balls.radius[i];
      const std::int32_t clump_i = balls.clump[i];
      const std::size_t first = keys.size();
      const std::int64_t cx = g.of(xi, 0), cy = g.of(xi, 1);
      const std::int64_t cz = dim == 3 ? g.of(xi, 2) : 0;
      for (std::int64_t z = std::max<std::int64_t>(cz - 1, 0);
           z <= std::min<std::int64_t>(cz + 1, g.nc[2] - 1); ++z)
        for (std::int64_t y = std::max<std::int64_t>(cy - 1, 0);
             y <= std::min<std::int64_t>(cy + 1, g.nc[1] - 1); ++y)
          for (std::int64_t x = std::max<std::int64_t>(cx - 1, 0);
               x <= std::min<std::int64_t>(cx + 1, g.nc[0] - 1); ++x) {
            const std::size_t c = g.index(x, y, z);
            for (std::int32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
              const std::size_t j = static_cast<std::size_t>(cell_items_[k]);
              if (j <= i || (clump_i >= 0 && balls.clump[j] == clump_i))
                continue; // pebbles of one clump never touch
              const double reach = ri + balls.radius[j] + margin_;
              if ((balls.pos[j] - xi).squaredNorm() < reach * reach)
                keys.push_back(contact_key(ContactKind::BallBall, static_cast<std::int32_t>(i),
                                           static_cast<std::int32_t>(j)));
            }
          }
      std::sort(keys.begin() + static_cast<std::ptrdiff_t>(first), keys.end());
      for (std::size_t w = 0; w < walls.size(); ++w) {
        const Wall& wall = walls[w];
        const double reach = ri + margin_;
        if ((xi.array() < wall.lo.array() - reach).any() ||
            (xi.array() > wall.hi.array() + reach).any())
          continue;
        if ((wall.closest_point(xi) - xi).norm() < reach)
          keys.push_back(contact_key(ContactKind::BallFacet, static_cast<std::int32_t>(i),
                                     static_cast<std::int32_t>(w)));
      }
    }
  }
  // Static scheduling hands out ascending index ranges in thread order, so concatenation
  // gives the same sorted list at any thread count.
  for (const auto& keys : thread_keys_)
    candidate_keys_.insert(candidate_keys_.end(), keys.begin(), keys.end());
}

void Model::merge_candidates() {
  // Merge the candidates with the existing contacts (both sorted by key): decide which stay and
  // make the new ones (events in key order), then rebuild the list in place (contact_list.cpp).
  assert(std::adjacent_find(candidate_keys_.begin(), candidate_keys_.end(),
                            std::greater_equal<>()) == candidate_keys_.end() &&
         "candidate keys sorted and unique");
  assert(std::adjacent_find(contacts_.begin(), contacts_.end(),
                            [](const Contact& x, const Contact& y) { return x.key >= y.key; }) ==
             contacts_.end() &&
         "contacts sorted by key");
  keep_.assign(contacts_.size(), 1);
  order_.clear();
  std::size_t a = 0, b = 0;
  while (a < contacts_.size() || b < candidate_keys_.size()) {
    if (b == candidate_keys_.size() ||
        (a < contacts_.size() && contacts_[a].key < candidate_keys_[b])) {
      const Contact& c = contacts_[a];
      if (contact_keeps_alive(batches_, c.model, c.slot)) {
        order_.push_back(0);
      } else {
        keep_[a] = 0;
        retire_contact(a);
      }
      ++a;
    } else if (a == contacts_.size() || candidate_keys_[b] < contacts_[a].key) {
      create_contact(candidate_keys_[b++]);
    } else {
      order_.push_back(0);
      ++a;
      ++b;
    }
  }
  rebuild_contacts();
}

void Model::retire_contact(std::size_t ci) {
  const Contact& c = contacts_[ci];
  retire_dissipation(c);
  Event ev;
  ev.type = EventType::ContactDeleted;
  ev.step = step_;
  ev.time = time_;
  ev.contact = c.key;
  ev.position = outputs_[ci].xc;
  ev.normal = c.n;
  ev.gap = c.gap;
  pending_events_.push_back(ev);
}

void Model::create_contact(std::uint64_t key) {
  const ContactEnds ends = contact_ends(key);
  assert(contact_key(ends.kind, ends.end1, ends.end2) == key && "a key decodes to its ends");
  const std::int32_t end1 = ends.end1, end2 = ends.end2;
  const bool facet = ends.kind == ContactKind::BallFacet;
  const ModelRule* rule = nullptr;
  for (const ModelRule& r : rules) {
    const bool ok = facet ? rule_matches_facet(r, balls.group[end1], end2)
                          : rule_matches_balls(r, balls.group[end1], balls.group[end2]);
    if (ok) {
      rule = &r;
      break;
    }
  }
  if (!rule)
    return; // no rule: the pieces do not interact
  Contact c;
  c.key = key;
  c.end1 = end1;
  c.end2 = end2;
  c.kind = ends.kind;
  c.model = kind_of(rule->props);
  CreationInfo info;
  info.dim = settings.dim;
  info.R1 = balls.radius[end1];
  info.R2 = facet ? 0.0 : balls.radius[end2];
  info.ball_facet = facet;
  const Vec3& x1 = balls.pos[end1];
  const PlaneGeometry g =
      facet ? ball_facet_plane(x1, info.R1, walls[static_cast<std::size_t>(end2)].closest_point(x1))
            : ball_ball_plane(x1, info.R1, balls.pos[end2], info.R2);
  info.gap = g.gap;
  info.n = g.n;
  if (rule->inherit && !facet) {
    const SurfaceProps none;
    auto surf = [&](std::int32_t grp) {
      return static_cast<std::size_t>(grp) < surface.size() ? surface[static_cast<std::size_t>(grp)]
                                                            : none;
    };
    ModelProps props = rule->props;
    inherit_properties(props, surf(balls.group[end1]), surf(balls.group[end2]));
    c.slot = create_contact_data(added_batches_, props, info);
  } else {
    c.slot = create_contact_data(added_batches_, rule->props, info);
  }
  ContactOutput o;
  o.stiff = contact_stiffness(added_batches_, c.model, c.slot);
  added_contacts_.push_back(c);
  added_outputs_.push_back(o);
  order_.push_back(1);
  Event ev;
  ev.type = EventType::ContactCreated;
  ev.step = step_;
  ev.time = time_;
  ev.contact = key;
  pending_events_.push_back(ev);
}

void Model::rebuild_adjacency() {
  // Ball -> contact adjacency in contact order, for a deterministic force sum.
  ++adjacency_generation_;
  const std::size_t n = balls.size();
  adj_start_.assign(n + 1, 0);
  for (const Contact& c : contacts_) {
    ++adj_start_[static_cast<std::size_t>(c.end1) + 1];
    if (c.kind == ContactKind::BallBall)
      ++adj_start_[static_cast<std::size_t>(c.end2) + 1];
  }
  for (std::size_t i = 0; i < n; ++i)
    adj_start_[i + 1] += adj_start_[i];
  adj_items_.resize(static_cast<std::size_t>(adj_start_[n]));
  {
    std::vector<std::int32_t>& cursor = adj_cursor_; // reused: no allocation once sized
    cursor.assign(adj_start_.begin(), adj_start_.end() - 1);
    facet_contacts_.clear();
    for (std::size_t ci = 0; ci < contacts_.size(); ++ci) {
      const Contact& c = contacts_[ci];
      if (c.kind == ContactKind::BallFacet)
        facet_contacts_.push_back(static_cast<std::int32_t>(ci));
      adj_items_[static_cast<std::size_t>(cursor[static_cast<std::size_t>(c.end1)]++)] =
          static_cast<std::int32_t>(2 * ci);
      if (c.kind == ContactKind::BallBall)
        adj_items_[static_cast<std::size_t>(cursor[static_cast<std::size_t>(c.end2)]++)] =
            static_cast<std::int32_t>(2 * ci + 1);
    }
  }
}

} // namespace rocklab
