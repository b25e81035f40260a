// Editing a model between cycles: clumps, contact-model methods and properties, the margin, and
// removing walls or balls (contacts compacted in order, their dissipation kept in the ledger).
#include "core/model.hpp"
#include "core/spatial_order.hpp"

#include "core/parallel.hpp"
#include <Eigen/Eigenvalues>

#include <functional>
#include <stdexcept>

namespace rocklab {

using namespace detail;

std::size_t Model::add_clump(const std::vector<Pebble>& pebbles, double density, int group,
                             std::int64_t id, std::int64_t first_pebble_id, const Vec3& velocity,
                             const Vec3& spin) {
  const int dim = settings.dim;
  const MassProperties mp = union_mass_properties(pebbles, density, dim);
  Clump c;
  c.id = id;
  c.group = group;
  c.mass = mp.mass;
  c.pos = mp.centroid;
  c.vel = velocity;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (dim == 3) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(mp.inertia);
    R = es.eigenvectors();
    if (R.determinant() < 0)
      R.col(2) *= -1;
    c.inertia = es.eigenvalues();
  } else {
    c.inertia = Vec3::Constant(mp.inertia(2, 2));
  }
  c.q = Eigen::Quaterniond(R);
  c.q.normalize();
  c.spin = dim == 2 ? Vec3(0, 0, spin.z()) : spin;
  c.L = R * c.inertia.asDiagonal() * R.transpose() * c.spin;
  double vsum = 0;
  for (const Pebble& p : pebbles)
    vsum += dim == 2 ? p.radius * p.radius : p.radius * p.radius * p.radius;
  const std::int32_t index = static_cast<std::int32_t>(clumps.size());
  for (std::size_t a = 0; a < pebbles.size(); ++a) {
    const Pebble& p = pebbles[a];
    const std::size_t i = balls.add(dim, first_pebble_id + static_cast<std::int64_t>(a), p.position,
                                    p.radius, density, group);
    // A pebble's own mass and inertia only enter the time-step estimate and dashpots: its
    // share of the union by volume.
    const double share = (dim == 2 ? p.radius * p.radius : p.radius * p.radius * p.radius) / vsum;
    balls.mass[i] = c.mass * share;
    balls.inertia[i] = (dim == 2 ? 0.5 : 0.4) * balls.mass[i] * p.radius * p.radius;
    balls.clump[i] = index;
    const Vec3 arm = p.position - c.pos;
    balls.vel[i] = c.vel + c.spin.cross(arm);
    balls.spin[i] = c.spin;
    c.pebbles.push_back(static_cast<std::int32_t>(i));
    c.offset.push_back(R.transpose() * arm);
  }
  clumps.push_back(std::move(c));
  return static_cast<std::size_t>(index);
}

std::size_t Model::apply_method(ModelKind kind, const std::string& method, double gap_lo,
                                double gap_hi, int element, bool gap_ratio) {
  std::size_t count = 0;
  visit_model(kind, [&]<class M>() {
    Batch<M>& batch = batches_.of<M>();
    for (std::size_t ci = 0; ci < contacts_.size(); ++ci) {
      Contact& c = contacts_[ci];
      if (c.model != kind)
        continue;
      ++count;
      if constexpr (HasMethods<M>) {
        double scale = 1;
        if (gap_ratio) {
          scale = balls.radius[static_cast<std::size_t>(c.end1)];
          if (c.kind == ContactKind::BallBall)
            scale += balls.radius[static_cast<std::size_t>(c.end2)];
        }
        const MethodArgs args{method,  scale * gap_lo, scale * gap_hi,
                              element, c.gap,          outputs_[ci].force};
        with_contact<M>(batch, c.slot, [&](auto&&... x) { M::call(x..., args); });
      }
      outputs_[ci].stiff = M::stiffness(batch.contacts[c.slot]);
    }
  });
  return count;
}

std::size_t Model::set_property(ModelKind kind, const std::string& name, double value,
                                ContactSelect which) {
  std::size_t count = 0;
  visit_model(kind, [&]<class M>() {
    typename M::Contact probe{};
    if (!M::property(probe, name))
      throw std::invalid_argument("contact property '" + name + "' is not a property of model '" +
                                  std::string(M::name) + "'");
    Batch<M>& batch = batches_.of<M>();
    for (std::size_t ci = 0; ci < contacts_.size(); ++ci) {
      const Contact& c = contacts_[ci];
      if (c.model != kind ||
          (which == ContactSelect::BallBall && c.kind != ContactKind::BallBall) ||
          (which == ContactSelect::BallFacet && c.kind != ContactKind::BallFacet))
        continue;
      ++count;
      *M::property(batch.contacts[c.slot], name) = value;
      outputs_[ci].stiff = M::stiffness(batch.contacts[c.slot]);
    }
  });
  return count;
}

void Model::set_margin(double margin) {
  settings.margin = margin;
  margin_ = margin;
  if (initialized_)
    detect();
}

void Model::remove_walls(const std::vector<bool>& remove) {
  std::vector<std::int32_t> map(walls.size(), -1);
  std::vector<Wall> kept;
  for (std::size_t w = 0; w < walls.size(); ++w)
    if (!remove[w]) {
      map[w] = static_cast<std::int32_t>(kept.size());
      kept.push_back(walls[w]);
    }
  compact_contacts([&](Contact& c) {
    if (c.kind == ContactKind::BallFacet) {
      if (remove[static_cast<std::size_t>(c.end2)])
        return false;
      c.end2 = map[static_cast<std::size_t>(c.end2)];
    }
    return true;
  });
  walls = std::move(kept);
  for (ModelRule& r : rules)
    if (r.wall >= 0) // a rule for a removed wall never matches again (-2)
      r.wall =
          map[static_cast<std::size_t>(r.wall)] >= 0 ? map[static_cast<std::size_t>(r.wall)] : -2;
  if (initialized_)
    detect();
}

void Model::replace_contact_model(std::size_t ci, const ModelProps& props) {
  Contact& c = contacts_[ci];
  retire_dissipation(c); // the old data is dropped when the list is next rebuilt (packed)
  CreationInfo info;
  info.dim = settings.dim;
  info.R1 = balls.radius[static_cast<std::size_t>(c.end1)];
  info.ball_facet = c.kind == ContactKind::BallFacet;
  info.R2 = info.ball_facet ? 0.0 : balls.radius[static_cast<std::size_t>(c.end2)];
  info.gap = c.gap;
  info.n = c.n;
  c.model = kind_of(props);
  c.slot = create_contact_data(batches_, props, info);
  outputs_[ci].stiff = contact_stiffness(batches_, c.model, c.slot);
}

void Model::remove_balls(const std::vector<bool>& remove) {
  const std::size_t n = balls.size();
  std::vector<std::int32_t> map(n, -1);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!remove[i])
      map[i] = static_cast<std::int32_t>(kept++);
  for (const Clump& c : clumps) {
    std::size_t gone = 0;
    for (std::int32_t p : c.pebbles)
      gone += remove[static_cast<std::size_t>(p)] ? 1 : 0;
    if (gone != 0 && gone != c.pebbles.size())
      throw std::invalid_argument("cannot remove part of clump " + std::to_string(c.id));
  }
  for (std::size_t i = 0; i < n; ++i)
    if (remove[i] && balls.clump[i] < 0) {
      const std::size_t g = static_cast<std::size_t>(balls.group[i]);
      if (group_retired_.size() <= g)
        group_retired_.resize(g + 1);
      group_retired_[g].body_work += balls.body_work[i];
      group_retired_[g].gravity_work += balls.gravity_work[i];
      group_retired_[g].local_damping += balls.damping_work[i];
    }
  auto compact = [&](auto& v) {
    std::size_t j = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (!remove[i])
        v[j++] = v[i];
    v.resize(kept);
  };
  balls.for_each_array(compact);
  mass_scale_.clear(); // density scaling ends with a change of the balls
  inertia_scale_.clear();
  // Clumps go whole or stay whole; the work of what goes stays in the group totals.
  std::vector<Clump> kept_clumps;
  for (Clump& c : clumps) {
    if (remove[static_cast<std::size_t>(c.pebbles.front())]) {
      const std::size_t g = static_cast<std::size_t>(c.group);
      if (group_retired_.size() <= g)
        group_retired_.resize(g + 1);
      group_retired_[g].body_work += c.body_work;
      group_retired_[g].gravity_work += c.gravity_work;
      group_retired_[g].local_damping += c.local_damping;
      continue;
    }
    for (std::int32_t& p : c.pebbles)
      p = map[static_cast<std::size_t>(p)];
    kept_clumps.push_back(std::move(c));
  }
  clumps = std::move(kept_clumps);
  for (std::size_t k = 0; k < clumps.size(); ++k)
    for (std::int32_t p : clumps[k].pebbles)
      balls.clump[static_cast<std::size_t>(p)] = static_cast<std::int32_t>(k);
  // Contacts of removed balls go; the others keep their order (the index map is monotonic).
  compact_contacts([&](Contact& c) {
    const bool bb = c.kind == ContactKind::BallBall;
    if (remove[static_cast<std::size_t>(c.end1)] ||
        (bb && remove[static_cast<std::size_t>(c.end2)]))
      return false;
    c.end1 = map[static_cast<std::size_t>(c.end1)];
    if (bb)
      c.end2 = map[static_cast<std::size_t>(c.end2)];
    return true;
  });
  if (initialized_)
    detect(); // rebuilds the adjacency; new candidates may appear
}

void Model::renumber_balls(const std::vector<std::size_t>& order) {
  const std::size_t n = balls.size();
  if (initialized_ || !contacts_.empty())
    throw std::logic_error("renumber_balls: only before the model is initialized");
  if (order.size() != n)
    throw std::invalid_argument("renumber_balls: the order must name every ball once");
  std::vector<std::int32_t> map(n, -1); // old index -> new
  for (std::size_t k = 0; k < n; ++k) {
    if (order[k] >= n || map[order[k]] >= 0)
      throw std::invalid_argument("renumber_balls: the order must name every ball once");
    map[order[k]] = static_cast<std::int32_t>(k);
  }
  balls.for_each_array([&](auto& v) {
    auto moved = v;
    for (std::size_t k = 0; k < n; ++k)
      moved[k] = v[order[k]];
    v = std::move(moved);
  });
  for (Clump& c : clumps)
    for (std::int32_t& p : c.pebbles)
      p = map[static_cast<std::size_t>(p)];
  mass_scale_.clear();
  inertia_scale_.clear();
}

bool Model::renumber_spatially() {
  const std::size_t n = balls.size();
  if (n < kRenumberMin)
    return false;
  double r_sum = 0, step_sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    r_sum += balls.radius[i];
    if (i > 0)
      step_sum += (balls.pos[i] - balls.pos[i - 1]).norm();
  }
  const double r_avg = r_sum / static_cast<double>(n);
  if (step_sum / static_cast<double>(n - 1) <= kOrderedStep * r_avg)
    return false; // already near spatial order: keep the user's numbering
  renumber_balls(morton_order(balls.pos, settings.dim, 2 * r_avg));
  return true;
}

} // namespace rocklab
