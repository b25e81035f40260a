#include "core/model.hpp"

#include "core/geometry.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <omp.h>
#include <sstream>

namespace rocklab {

namespace {

constexpr std::size_t kBlock = 2048; // fixed reduction block: sums do not depend on threads
// Loops shorter than this run on the calling thread: forking costs more than it saves, and on a
// busy machine a barrier can cost a whole scheduler time slice. Results do not depend on it.
constexpr std::size_t kParallelMin = 1024;

/// Sum K quantities over n items in fixed blocks, so the result is bit-identical at any thread
/// count. f(i, acc) adds item i's contributions into acc[0..K).
template <int K, class F> std::array<double, K> block_sum(std::size_t n, F&& f) {
  const std::size_t nblocks = (n + kBlock - 1) / kBlock;
  std::array<double, K> total{};
  if (nblocks == 0)
    return total;
  // Small stack buffer for the common case; larger models use a heap buffer once per call.
  constexpr std::size_t kStack = 256;
  std::array<std::array<double, K>, kStack> stack_parts;
  std::vector<std::array<double, K>> heap_parts;
  std::array<double, K>* parts = stack_parts.data();
  if (nblocks > kStack) {
    heap_parts.resize(nblocks);
    parts = heap_parts.data();
  }
#pragma omp parallel for schedule(static) if (n >= kParallelMin)
  for (std::size_t b = 0; b < nblocks; ++b) {
    std::array<double, K> acc{};
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i)
      f(i, acc);
    parts[b] = acc;
  }
  for (std::size_t b = 0; b < nblocks; ++b)
    for (int k = 0; k < K; ++k)
      total[k] += parts[b][k];
  return total;
}

double sign(double v) {
  return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0);
}

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

int Model::group_index(const std::string& name) {
  for (std::size_t i = 0; i < group_names.size(); ++i)
    if (group_names[i] == name)
      return static_cast<int>(i);
  group_names.push_back(name);
  return static_cast<int>(group_names.size() - 1);
}

void Model::ensure_thread_buffers() {
  // Per-thread buffers are indexed by thread number; the thread count may change between calls.
  const std::size_t nthreads = static_cast<std::size_t>(omp_get_max_threads());
  if (thread_events_.size() < nthreads)
    thread_events_.resize(nthreads);
  if (thread_keys_.size() < nthreads)
    thread_keys_.resize(nthreads);
}

void Model::initialize() {
  ensure_thread_buffers();
  for (auto& w : walls)
    w.update_bounds();
  margin_ = settings.margin;
  if (margin_ <= 0) {
    double sum = 0;
    for (double r : balls.radius)
      sum += r;
    margin_ = balls.size() ? 0.1 * sum / static_cast<double>(balls.size()) : 0.0;
  }
  // The speed cap of the automatic step needs the initial velocities before the first step.
  max_speed_ = 0;
  for (std::size_t i = 0; i < balls.size(); ++i)
    max_speed_ = std::max(max_speed_, balls.vel[i].norm() + balls.radius[i] * balls.spin[i].norm());
  detect();
  force_displacement(0.0);
  const EnergyLedger e = energy();
  ledger_.initial_total = e.kinetic() + e.stored();
  initialized_ = true;
}

bool Model::needs_detection() const {
  return 2.0 * max_ball_disp_ + wall_disp_ >= margin_;
}

void Model::detect() {
  const std::size_t n = balls.size();
  const int dim = settings.dim;
  const std::size_t nthreads = thread_keys_.size();
  for (auto& k : thread_keys_)
    k.clear();
  candidate_keys_.clear();

  if (n > 0) {
    // Cell grid: cells at least one interaction range wide, so only neighbour cells can pair.
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max());
    Vec3 hi = -lo;
    double rmax = 0;
    for (std::size_t i = 0; i < n; ++i) {
      lo = lo.cwiseMin(balls.pos[i]);
      hi = hi.cwiseMax(balls.pos[i]);
      rmax = std::max(rmax, balls.radius[i]);
    }
    double cell = std::max(2.0 * rmax + margin_, 1e-300);
    std::array<std::int64_t, 3> nc{1, 1, 1};
    for (;;) {
      for (int d = 0; d < dim; ++d)
        nc[d] = static_cast<std::int64_t>((hi[d] - lo[d]) / cell) + 1;
      if (nc[0] * nc[1] * nc[2] <= static_cast<std::int64_t>(std::max<std::size_t>(8 * n, 64)))
        break;
      cell *= 1.25;
    }
    const std::size_t ncells = static_cast<std::size_t>(nc[0] * nc[1] * nc[2]);
    auto cell_of = [&](const Vec3& x, int axis) {
      return std::clamp<std::int64_t>(static_cast<std::int64_t>((x[axis] - lo[axis]) / cell), 0,
                                      nc[axis] - 1);
    };
    auto cell_index = [&](std::int64_t cx, std::int64_t cy, std::int64_t cz) {
      return static_cast<std::size_t>((cz * nc[1] + cy) * nc[0] + cx);
    };
    cell_start_.assign(ncells + 1, 0);
    cell_items_.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      ++cell_start_[cell_index(cell_of(balls.pos[i], 0), cell_of(balls.pos[i], 1),
                               dim == 3 ? cell_of(balls.pos[i], 2) : 0) +
                    1];
    for (std::size_t c = 0; c < ncells; ++c)
      cell_start_[c + 1] += cell_start_[c];
    {
      std::vector<std::int32_t>& fill = adj_items_; // reuse as a cursor buffer
      fill.assign(cell_start_.begin(), cell_start_.end() - 1);
      for (std::size_t i = 0; i < n; ++i) {
        const std::size_t c = cell_index(cell_of(balls.pos[i], 0), cell_of(balls.pos[i], 1),
                                         dim == 3 ? cell_of(balls.pos[i], 2) : 0);
        cell_items_[static_cast<std::size_t>(fill[c]++)] = static_cast<std::int32_t>(i);
      }
    }

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
        const std::int64_t cx = cell_of(xi, 0), cy = cell_of(xi, 1);
        const std::int64_t cz = dim == 3 ? cell_of(xi, 2) : 0;
        for (std::int64_t z = std::max<std::int64_t>(cz - 1, 0);
             z <= std::min<std::int64_t>(cz + 1, nc[2] - 1); ++z)
          for (std::int64_t y = std::max<std::int64_t>(cy - 1, 0);
               y <= std::min<std::int64_t>(cy + 1, nc[1] - 1); ++y)
            for (std::int64_t x = std::max<std::int64_t>(cx - 1, 0);
                 x <= std::min<std::int64_t>(cx + 1, nc[0] - 1); ++x) {
              const std::size_t c = cell_index(x, y, z);
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
    for (std::size_t t = 0; t < nthreads; ++t)
      candidate_keys_.insert(candidate_keys_.end(), thread_keys_[t].begin(), thread_keys_[t].end());
  }

  // Merge the candidates with the existing contacts (both sorted by key).
  new_contacts_.clear();
  new_outputs_.clear();
  new_batches_.clear();
  std::size_t a = 0, b = 0;
  auto keep = [&](std::size_t ci) {
    Contact c = contacts_[ci];
    c.slot = move_contact_data(new_batches_, batches_, c.model, c.slot);
    new_contacts_.push_back(c);
    new_outputs_.push_back(outputs_[ci]);
  };
  auto retire = [&](std::size_t ci) {
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
  };
  auto create = [&](std::uint64_t key) {
    const auto end1 = static_cast<std::int32_t>(key >> 32);
    const bool facet = ((key >> 31) & 1u) != 0;
    const auto end2 = static_cast<std::int32_t>(key & 0x7fffffffu);
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
      return;
    Contact c;
    c.key = key;
    c.end1 = end1;
    c.end2 = end2;
    c.kind = facet ? ContactKind::BallFacet : ContactKind::BallBall;
    c.model = kind_of(rule->props);
    CreationInfo info;
    info.dim = settings.dim;
    info.R1 = balls.radius[end1];
    info.R2 = facet ? 0.0 : balls.radius[end2];
    info.ball_facet = facet;
    const Vec3& x1 = balls.pos[end1];
    if (facet) {
      const PlaneGeometry g =
          ball_facet_plane(x1, info.R1, walls[static_cast<std::size_t>(end2)].closest_point(x1));
      info.gap = g.gap;
      info.n = g.n;
    } else {
      const PlaneGeometry g = ball_ball_plane(x1, info.R1, balls.pos[end2], info.R2);
      info.gap = g.gap;
      info.n = g.n;
    }
    if (rule->inherit && !facet) {
      const SurfaceProps none;
      auto surf = [&](std::int32_t g) {
        return static_cast<std::size_t>(g) < surface.size() ? surface[static_cast<std::size_t>(g)]
                                                            : none;
      };
      ModelProps props = rule->props;
      inherit_properties(props, surf(balls.group[end1]), surf(balls.group[end2]));
      c.slot = create_contact_data(new_batches_, props, info);
    } else {
      c.slot = create_contact_data(new_batches_, rule->props, info);
    }
    ContactOutput o;
    o.stiff = contact_stiffness(new_batches_, c.model, c.slot);
    new_contacts_.push_back(c);
    new_outputs_.push_back(o);
    Event ev;
    ev.type = EventType::ContactCreated;
    ev.step = step_;
    ev.time = time_;
    ev.contact = key;
    pending_events_.push_back(ev);
  };
  while (a < contacts_.size() || b < candidate_keys_.size()) {
    if (b == candidate_keys_.size() ||
        (a < contacts_.size() && contacts_[a].key < candidate_keys_[b])) {
      const Contact& c = contacts_[a];
      const bool alive = contact_keeps_alive(batches_, c.model, c.slot);
      if (alive)
        keep(a);
      else
        retire(a);
      ++a;
    } else if (a == contacts_.size() || candidate_keys_[b] < contacts_[a].key) {
      create(candidate_keys_[b++]);
    } else {
      keep(a++);
      ++b;
    }
  }
  std::swap(contacts_, new_contacts_);
  std::swap(outputs_, new_outputs_);
  std::swap(batches_, new_batches_);

  rebuild_adjacency();
  for (auto& d : balls.disp)
    d.setZero();
  max_ball_disp_ = 0;
  wall_disp_ = 0;
}

void Model::rebuild_adjacency() {
  // Ball -> contact adjacency in contact order, for a deterministic force sum.
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
    for (std::size_t ci = 0; ci < contacts_.size(); ++ci) {
      const Contact& c = contacts_[ci];
      adj_items_[static_cast<std::size_t>(cursor[static_cast<std::size_t>(c.end1)]++)] =
          static_cast<std::int32_t>(2 * ci);
      if (c.kind == ContactKind::BallBall)
        adj_items_[static_cast<std::size_t>(cursor[static_cast<std::size_t>(c.end2)]++)] =
            static_cast<std::int32_t>(2 * ci + 1);
    }
  }
}

void Model::retire_dissipation(const Contact& c) {
  // Dissipation so far stays in the ledger; stored energy leaves with the contact.
  ContactEnergy e = contact_energy(batches_, c.model, c.slot);
  e.strain = e.bond_strain = 0;
  retired_ += e;
  share_contact_energy(c, e, group_retired_);
}

void Model::share_contact_energy(const Contact& c, const ContactEnergy& e,
                                 std::vector<EnergyLedger>& out) const {
  // Thesis section 3: a contact inside one group counts fully to it, a contact between two
  // groups half to each; a wall is in no group.
  auto add = [&](std::int32_t g, double f) {
    const std::size_t k = static_cast<std::size_t>(g);
    if (out.size() <= k)
      out.resize(k + 1);
    EnergyLedger& l = out[k];
    l.strain += f * e.strain;
    l.bond_strain += f * e.bond_strain;
    l.slip += f * e.slip;
    l.dashpot += f * e.dashpot;
    l.plastic += f * e.plastic;
  };
  const std::int32_t g1 = balls.group[static_cast<std::size_t>(c.end1)];
  if (c.kind == ContactKind::BallFacet) {
    add(g1, 1.0);
    return;
  }
  const std::int32_t g2 = balls.group[static_cast<std::size_t>(c.end2)];
  if (g1 == g2) {
    add(g1, 1.0);
  } else {
    add(g1, 0.5);
    add(g2, 0.5);
  }
}

void Model::force_displacement(double dt) {
  const int dim = settings.dim;
  const std::size_t nc = contacts_.size();
  const std::size_t none = std::numeric_limits<std::size_t>::max();
  std::size_t blowup = none;
  for (auto& buf : thread_events_)
    buf.clear();

#pragma omp parallel reduction(min : blowup) if (nc >= kParallelMin)
  {
    EventBuffer& events = thread_events_[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(static)
    for (std::size_t ci = 0; ci < nc; ++ci) {
      Contact& c = contacts_[ci];
      ContactOutput& out = outputs_[ci];
      const std::size_t i1 = static_cast<std::size_t>(c.end1);
      const Vec3& x1 = balls.pos[i1];
      const double R1 = balls.radius[i1];
      PlaneGeometry g;
      Vec3 xb2, v2, w2;
      double R2 = 0, m_eff = balls.mass[i1];
      if (c.kind == ContactKind::BallBall) {
        const std::size_t i2 = static_cast<std::size_t>(c.end2);
        R2 = balls.radius[i2];
        g = ball_ball_plane(x1, R1, balls.pos[i2], R2);
        xb2 = balls.pos[i2];
        v2 = balls.vel[i2];
        w2 = balls.spin[i2];
        m_eff = balls.mass[i1] * balls.mass[i2] / (balls.mass[i1] + balls.mass[i2]);
      } else {
        const Wall& wall = walls[static_cast<std::size_t>(c.end2)];
        g = ball_facet_plane(x1, R1, wall.closest_point(x1, &c.facet));
        xb2 = wall.center;
        // A radially moving wall adds its radial speed at the contact point.
        v2 = wall.radial_velocity != 0
                 ? Vec3(wall.velocity + wall.radial_velocity * wall.radial_dir(g.xc))
                 : wall.velocity;
        w2 = wall.spin;
      }
      const bool fresh = !c.initialized;
      if (fresh) {
        if (dim == 2) {
          c.s = -Vec3::UnitZ();
          c.t = Vec3::UnitZ().cross(g.n);
        } else {
          c.s = initial_s_axis(g.n);
          c.t = g.n.cross(c.s);
        }
        c.initialized = true;
      } else {
        update_plane_axes(dim, c.n, g.n, balls.spin[i1], w2, dt, c.s, c.t);
      }
      // Blow-up: overlap beyond a radius. A facet contact measures an unsigned distance, so
      // there the overlap reaching the radius shows as the normal flipping within one step.
      const bool through = c.kind == ContactKind::BallFacet && !fresh && g.n.dot(c.n) < 0;
      if ((settings.overlap_check &&
           (g.gap < -std::min(R1, c.kind == ContactKind::BallBall ? R2 : R1) || through)) ||
          !std::isfinite(g.gap))
        blowup = std::min(blowup, ci);
      out.xc = g.xc;
      c.n = g.n;
      c.gap = g.gap;

      ContactKinematics k;
      k.dt = dt;
      k.dim = dim;
      k.gap = g.gap;
      k.R1 = R1;
      k.R2 = R2;
      k.mass_eff = m_eff;
      k.ball_facet = c.kind == ContactKind::BallFacet;
      relative_increments(out.xc, c.n, c.s, c.t, x1, balls.vel[i1], balls.spin[i1], xb2, v2, w2, dt,
                          k);
      const std::size_t first_event = events.size();
      EventSink sink{&events, c.key, 0, settings.slip_events};
      k.n = c.n;
      k.s = c.s;
      k.t = c.t;
      ContactResult r;
      update_contact(batches_, c.model, c.slot, k, r, sink);
      out.stiff = contact_stiffness(batches_, c.model, c.slot);
      out.force = -r.Fn * c.n + r.Fss * c.s + r.Fst * c.t;
      out.moment = r.Mt * c.n + r.Mbs * c.s + r.Mbt * c.t;
      for (std::size_t e = first_event; e < events.size(); ++e) {
        Event& ev = events[e];
        ev.step = step_;
        ev.time = time_;
        ev.normal = c.n;
        ev.position = out.xc + ev.position.y() * c.s + ev.position.z() * c.t;
        if (ev.gap == 0)
          ev.gap = c.gap;
      }
    }
  }

  // Events in a fixed order: by contact, then by the order a contact raised them.
  const std::size_t before = pending_events_.size();
  for (auto& buf : thread_events_)
    pending_events_.insert(pending_events_.end(), buf.begin(), buf.end());
  std::sort(pending_events_.begin() + static_cast<std::ptrdiff_t>(before), pending_events_.end(),
            [](const Event& x, const Event& y) {
              return x.contact != y.contact ? x.contact < y.contact : x.seq < y.seq;
            });
  for (std::size_t k = before; k < pending_events_.size(); ++k) {
    const Event& ev = pending_events_[k];
    if (ev.type != EventType::BondBreak || ev.energy == 0)
      continue;
    // The released bond energy leaves the stored partitions: book it, shared like the contact.
    ledger_.bond_break += ev.energy;
    const ContactEnds ends = contact_ends(ev.contact);
    Contact c;
    c.kind = ends.kind;
    c.end1 = ends.end1;
    c.end2 = ends.end2;
    ContactEnergy released;
    released.bond_strain = ev.energy;
    share_contact_energy(c, released, broken_);
  }

  // Sum contact forces into balls, each ball over its contacts in contact order.
  const std::size_t n = balls.size();
  double dt_min = std::numeric_limits<double>::infinity();
#pragma omp parallel for schedule(static) reduction(min : dt_min) if (n >= kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    Vec3 F = Vec3::Zero(), M = Vec3::Zero();
    double k_tran = 0, k_rot = 0;
    const Vec3& xi = balls.pos[i];
    for (std::int32_t a = adj_start_[i]; a < adj_start_[i + 1]; ++a) {
      const std::int32_t item = adj_items_[static_cast<std::size_t>(a)];
      const ContactOutput& c = outputs_[static_cast<std::size_t>(item >> 1)];
      const double side = (item & 1) ? 1.0 : -1.0; // force acts on end2, reaction on end1
      const Vec3 f = side * c.force;
      const Vec3 arm = c.xc - xi;
      F += f;
      M += side * c.moment + arm.cross(f);
      k_tran += c.stiff.k_tran;
      k_rot += c.stiff.k_shear * arm.squaredNorm() + c.stiff.k_rot;
    }
    balls.force[i] = F;
    balls.moment[i] = M;
    if (k_tran > 0)
      dt_min = std::min(dt_min, std::sqrt(balls.mass[i] / k_tran));
    if (k_rot > 0)
      dt_min = std::min(dt_min, std::sqrt(balls.inertia[i] / k_rot));
  }
  dt_stiffness_ = dt_min;

  for (Wall& w : walls) {
    w.force.setZero();
    w.moment.setZero();
    w.radial_force = 0;
  }
  for (std::size_t ci = 0; ci < nc; ++ci) {
    const Contact& c = contacts_[ci];
    if (c.kind != ContactKind::BallFacet)
      continue;
    const ContactOutput& o = outputs_[ci];
    Wall& w = walls[static_cast<std::size_t>(c.end2)];
    w.force += o.force;
    w.moment += o.moment + (o.xc - w.center).cross(o.force);
    w.radial_force += o.force.dot(w.radial_dir(o.xc));
  }

  if (blowup != none) {
    const Contact& c = contacts_[blowup];
    std::ostringstream msg;
    msg << "physical blow-up at step " << step_ << " (t = " << time_
        << " s): overlap beyond a radius at the contact between ball id "
        << balls.id[static_cast<std::size_t>(c.end1)]
        << (c.kind == ContactKind::BallBall ? " and ball id " : " and wall ")
        << (c.kind == ContactKind::BallBall
                ? std::to_string(balls.id[static_cast<std::size_t>(c.end2)])
                : walls[static_cast<std::size_t>(c.end2)].name)
        << " (gap " << c.gap
        << " m, or the ball passed through the wall); reduce the time step, "
           "the loading rate or raise the stiffness";
    throw PhysicsError(msg.str());
  }
}

double Model::estimate_timestep() const {
  if (settings.timestep > 0)
    return settings.timestep;
  double dt = settings.timestep_safety * dt_stiffness_;
  // Nothing may move more than a quarter of the margin in one step, so that contacts exist
  // before the pieces touch.
  if (max_speed_ > 0)
    dt = std::min(dt, 0.25 * margin_ / max_speed_);
  const double g = settings.gravity.norm();
  if (g > 0)
    dt = std::min(dt, std::sqrt(0.25 * margin_ / g));
  for (const Wall& w : walls) {
    const double v = w.max_vertex_speed();
    if (v > 0)
      dt = std::min(dt, 0.25 * margin_ / v);
  }
  if (!std::isfinite(dt) || dt <= 0)
    dt = 1e-3; // nothing constrains the step: no contacts, no motion, no gravity
  return dt;
}

void Model::move_clumps(double dt, std::array<double, 4>& sums) {
  if (clumps.empty())
    return;
  const int dim = settings.dim;
  const double alpha = settings.local_damping;
  const Vec3 gvec = settings.gravity;
  const int ntran = dim == 2 ? 2 : 3;
  const auto s = block_sum<4>(clumps.size(), [&](std::size_t k, std::array<double, 4>& acc) {
    Clump& c = clumps[k];
    // Resultant about the centroid: pebble contact forces and moments, gravity on the union's
    // mass, applied loads.
    Vec3 F = Vec3::Zero(), M = Vec3::Zero();
    for (std::int32_t p : c.pebbles) {
      const std::size_t i = static_cast<std::size_t>(p);
      F += balls.force[i];
      M += balls.moment[i] + (balls.pos[i] - c.pos).cross(balls.force[i]);
    }
    const Vec3 Fg = c.mass * gvec;
    const Vec3 Fbody = Fg + c.applied_force;
    F += Fbody;
    M += c.applied_moment;
    double bw = 0, gw = 0, dw = 0;
    for (int d = 0; d < ntran; ++d) {
      const double v0 = c.vel[d];
      const double Fd = -alpha * std::abs(F[d]) * sign(v0);
      const double v1 = v0 + (F[d] + Fd) / c.mass * dt;
      c.vel[d] = v1;
      dw -= Fd * 0.5 * (v0 + v1) * dt;
      bw += Fbody[d] * 0.5 * (v0 + v1) * dt; // Eq. 2
      gw += Fg[d] * 0.5 * (v0 + v1) * dt;    // Eq. 3
    }
    const Vec3 w0 = c.spin;
    Vec3 Md = Vec3::Zero();
    for (int d = (dim == 2 ? 2 : 0); d < 3; ++d)
      Md[d] = -alpha * std::abs(M[d]) * sign(w0[d]);
    c.L += (M + Md) * dt;
    if (dim == 2)
      c.L.x() = c.L.y() = 0;
    Vec3 Lb = c.q.conjugate() * c.L;
    free_rotation(c.q, Lb, c.inertia, dt, dim);
    c.spin = c.q * Lb.cwiseQuotient(c.inertia);
    const Vec3 wm = 0.5 * (w0 + c.spin);
    dw -= Md.dot(wm) * dt;
    bw += c.applied_moment.dot(wm) * dt;
    c.pos += c.vel * dt;
    for (std::size_t a = 0; a < c.pebbles.size(); ++a) {
      const std::size_t i = static_cast<std::size_t>(c.pebbles[a]);
      const Vec3 arm = c.q * c.offset[a];
      const Vec3 x = c.pos + arm;
      balls.disp[i] += x - balls.pos[i];
      balls.pos[i] = x;
      balls.vel[i] = c.vel + c.spin.cross(arm);
      balls.spin[i] = c.spin;
    }
    c.body_work += bw;
    c.gravity_work += gw;
    c.local_damping += dw;
    acc[0] += bw;
    acc[1] += gw;
    acc[3] += dw;
  });
  for (int k = 0; k < 4; ++k)
    sums[static_cast<std::size_t>(k)] += s[static_cast<std::size_t>(k)];
}

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

std::vector<EnergyLedger> Model::group_energy() const {
  std::vector<EnergyLedger> out = group_retired_;
  out.resize(std::max({out.size(), group_names.size(), broken_.size()}));
  for (std::size_t g = 0; g < broken_.size(); ++g)
    out[g].bond_break += broken_[g].bond_strain; // released bond energy (kept in bond_strain)
  auto at = [&](std::int32_t g) -> EnergyLedger& {
    const std::size_t k = static_cast<std::size_t>(g);
    if (out.size() <= k)
      out.resize(k + 1);
    return out[k];
  };
  for (std::size_t i = 0; i < balls.size(); ++i) {
    if (balls.clump[i] >= 0)
      continue;
    EnergyLedger& l = at(balls.group[i]);
    l.kinetic_translational += 0.5 * balls.mass[i] * balls.vel[i].squaredNorm(); // Eq. 4
    l.kinetic_rotational += 0.5 * balls.inertia[i] * balls.spin[i].squaredNorm();
    l.body_work += balls.body_work[i];
    l.gravity_work += balls.gravity_work[i];
    l.local_damping += balls.damping_work[i];
  }
  for (const Clump& c : clumps) {
    EnergyLedger& l = at(c.group);
    l.kinetic_translational += c.kinetic_translational();
    l.kinetic_rotational += c.kinetic_rotational();
    l.body_work += c.body_work;
    l.gravity_work += c.gravity_work;
    l.local_damping += c.local_damping;
  }
  for (const Contact& c : contacts_)
    share_contact_energy(c, contact_energy(batches_, c.model, c.slot), out); // Eq. 5-6, 10
  return out;
}

void Model::law_of_motion(double dt) {
  const int dim = settings.dim;
  const double alpha = settings.local_damping;
  const Vec3 gvec = settings.gravity;
  const int ntran = dim == 2 ? 2 : 3;
  // acc: 0 body work, 1 gravity work, 2 boundary (constraint) work, 3 local damping, 4 max |v|
  // and 5 max displacement are handled with separate reductions below.
  double vmax = 0, dmax = 0, step_ratio = 0;
  bool bad = false;
  auto sums = block_sum<4>(balls.size(), [&](std::size_t i, std::array<double, 4>& acc) {
    if (balls.clump[i] >= 0)
      return; // pebbles move with their clump (move_clumps)
    const double m = balls.mass[i];
    double bw = 0, gw = 0, dw = 0; // this ball's body, gravity and damping work
    const std::uint8_t fix = balls.fixity[i];
    const Vec3 Fg = m * gvec;
    const Vec3 Fbody = Fg + balls.applied_force[i];
    const Vec3 F = balls.force[i] + Fbody;
    Vec3& v = balls.vel[i];
    for (int d = 0; d < ntran; ++d) {
      const double v0 = v[d];
      double v1 = v0;
      if (fix & dof_bit(d)) {
        acc[2] -= F[d] * v0 * dt; // the constraint force -F holds the velocity
      } else {
        const double Fd = -alpha * std::abs(F[d]) * sign(v0);
        v1 = v0 + (F[d] + Fd) / m * dt;
        dw -= Fd * 0.5 * (v0 + v1) * dt;
      }
      v[d] = v1;
      bw += Fbody[d] * 0.5 * (v0 + v1) * dt; // Eq. 2
      gw += Fg[d] * 0.5 * (v0 + v1) * dt;    // Eq. 3
    }
    const double I = balls.inertia[i];
    const Vec3 M = balls.moment[i] + balls.applied_moment[i];
    Vec3& w = balls.spin[i];
    for (int d = (dim == 2 ? 2 : 0); d < 3; ++d) {
      const double w0 = w[d];
      double w1 = w0;
      if (fix & dof_bit(3 + d)) {
        acc[2] -= M[d] * w0 * dt;
      } else {
        const double Md = -alpha * std::abs(M[d]) * sign(w0);
        w1 = w0 + (M[d] + Md) / I * dt;
        dw -= Md * 0.5 * (w0 + w1) * dt;
      }
      w[d] = w1;
      bw += balls.applied_moment[i][d] * 0.5 * (w0 + w1) * dt;
    }
    const Vec3 dx = v * dt;
    balls.pos[i] += dx;
    balls.disp[i] += dx;
    acc[0] += bw;
    acc[1] += gw;
    acc[3] += dw;
    balls.body_work[i] += bw;
    balls.gravity_work[i] += gw;
    balls.damping_work[i] += dw;
  });
  move_clumps(dt, sums);
  ledger_.body_work += sums[0];
  ledger_.gravity_work += sums[1];
  ledger_.boundary_work += sums[2];
  ledger_.local_damping += sums[3];

  const std::size_t n = balls.size();
#pragma omp parallel for schedule(static) reduction(max                                            \
                                                    : vmax, dmax, step_ratio)                      \
    reduction(||                                                                                   \
              : bad) if (n >= kParallelMin)
  for (std::size_t i = 0; i < n; ++i) {
    vmax = std::max(vmax, balls.vel[i].norm() + balls.radius[i] * balls.spin[i].norm());
    step_ratio = std::max(step_ratio, balls.vel[i].norm() * dt / balls.radius[i]);
    dmax = std::max(dmax, balls.disp[i].norm());
    bad = bad || !balls.pos[i].allFinite() || !balls.vel[i].allFinite();
  }
  max_speed_ = vmax;
  max_ball_disp_ = dmax;
  if (step_ratio > 1) {
    // A ball that moves more than its radius in one step can pass through a contact unseen.
    for (std::size_t i = 0; i < n; ++i)
      if (balls.vel[i].norm() * dt > balls.radius[i]) {
        std::ostringstream msg;
        msg << "physical blow-up at step " << step_ << " (t = " << time_ << " s): ball id "
            << balls.id[i] << " moved " << balls.vel[i].norm() * dt
            << " m in one step, more than its radius " << balls.radius[i]
            << " m; reduce the time step";
        throw PhysicsError(msg.str());
      }
  }
  if (bad) {
    for (std::size_t i = 0; i < n; ++i)
      if (!balls.pos[i].allFinite() || !balls.vel[i].allFinite()) {
        std::ostringstream msg;
        msg << "physical blow-up at step " << step_ << " (t = " << time_ << " s): ball id "
            << balls.id[i] << " has a non-finite position or velocity; reduce the time step";
        throw PhysicsError(msg.str());
      }
  }
}

void Model::cycle(std::int64_t count) {
  if (!initialized_)
    initialize();
  ensure_thread_buffers();
  for (std::int64_t k = 0; k < count; ++k) {
    const double dt = estimate_timestep();
    dt_ = dt;
    law_of_motion(dt);
    double wall_work = 0;
    for (Wall& w : walls) {
      // Energy a moving wall puts in: the force on the balls (-force) times the wall motion.
      wall_work -=
          (w.force.dot(w.velocity) + w.moment.dot(w.spin) + w.radial_force * w.radial_velocity) *
          dt;
      wall_disp_ += w.max_vertex_speed() * dt;
      w.move(dt);
    }
    ledger_.boundary_work += wall_work;
    time_ += dt;
    ++step_;
    if (needs_detection())
      detect();
    force_displacement(dt);
  }
}

EnergyLedger Model::energy() const {
  EnergyLedger e = ledger_;
  const auto kin = block_sum<2>(balls.size(), [&](std::size_t i, std::array<double, 2>& acc) {
    if (balls.clump[i] >= 0)
      return; // counted with the clump
    acc[0] += 0.5 * balls.mass[i] * balls.vel[i].squaredNorm();
    acc[1] += 0.5 * balls.inertia[i] * balls.spin[i].squaredNorm();
  });
  e.kinetic_translational = kin[0];
  e.kinetic_rotational = kin[1];
  for (const Clump& c : clumps) {
    e.kinetic_translational += c.kinetic_translational();
    e.kinetic_rotational += c.kinetic_rotational();
  }
  const auto con = block_sum<5>(contacts_.size(), [&](std::size_t ci, std::array<double, 5>& acc) {
    const Contact& c = contacts_[ci];
    const ContactEnergy ce = contact_energy(batches_, c.model, c.slot);
    acc[0] += ce.strain;
    acc[1] += ce.bond_strain;
    acc[2] += ce.slip;
    acc[3] += ce.dashpot;
    acc[4] += ce.plastic;
  });
  e.strain = con[0];
  e.bond_strain = con[1];
  e.slip = con[2] + retired_.slip;
  e.dashpot = con[3] + retired_.dashpot;
  e.plastic = con[4] + retired_.plastic;
  return e;
}

double Model::mean_unbalanced_force_ratio() const {
  const int ntran = settings.dim == 2 ? 2 : 3;
  const auto ub = block_sum<1>(balls.size(), [&](std::size_t i, std::array<double, 1>& acc) {
    if (balls.clump[i] >= 0)
      return;
    const Vec3 F = balls.force[i] + balls.mass[i] * settings.gravity + balls.applied_force[i];
    double s = 0;
    for (int d = 0; d < ntran; ++d)
      if (!(balls.fixity[i] & dof_bit(d)))
        s += F[d] * F[d];
    acc[0] += std::sqrt(s);
  });
  const auto cf = block_sum<2>(contacts_.size(), [&](std::size_t ci, std::array<double, 2>& acc) {
    const double f = outputs_[ci].force.norm();
    if (f > 0) {
      acc[0] += f;
      acc[1] += 1;
    }
  });
  double ub_sum = ub[0];
  std::size_t bodies = balls.size();
  for (const Clump& c : clumps) {
    Vec3 F = c.mass * settings.gravity + c.applied_force;
    for (std::int32_t p : c.pebbles)
      F += balls.force[static_cast<std::size_t>(p)];
    if (settings.dim == 2)
      F.z() = 0;
    ub_sum += F.norm();
    bodies -= c.pebbles.size() - 1;
  }
  const double mean_ub = bodies ? ub_sum / static_cast<double>(bodies) : 0.0;
  const double mean_cf = cf[1] > 0 ? cf[0] / cf[1] : 0.0;
  if (mean_cf <= 0)
    return mean_ub > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  return mean_ub / mean_cf;
}

void Model::drain_events(std::vector<Event>& out) {
  out.insert(out.end(), pending_events_.begin(), pending_events_.end());
  pending_events_.clear();
}

std::size_t Model::apply_method(ModelKind kind, const std::string& method, double gap_lo,
                                double gap_hi, int element) {
  std::size_t count = 0;
  visit_model(kind, [&]<class M>() {
    Batch<M>& batch = batches_.of<M>();
    for (std::size_t ci = 0; ci < contacts_.size(); ++ci) {
      Contact& c = contacts_[ci];
      if (c.model != kind)
        continue;
      ++count;
      if constexpr (HasMethods<M>) {
        const MethodArgs args{method, gap_lo, gap_hi, element, c.gap, outputs_[ci].force};
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

void Model::compact_contacts(const std::function<bool(Contact&)>& keep) {
  // Keep (and let `keep` renumber) some contacts in their order; the dropped ones retire their
  // dissipation. Model data is compacted into fresh batches.
  new_contacts_.clear();
  new_outputs_.clear();
  new_batches_.clear();
  for (std::size_t ci = 0; ci < contacts_.size(); ++ci) {
    Contact c = contacts_[ci];
    if (!keep(c)) {
      retire_dissipation(contacts_[ci]);
      continue;
    }
    c.key = contact_key(c.kind, c.end1, c.end2);
    c.slot = move_contact_data(new_batches_, batches_, c.model, c.slot);
    new_contacts_.push_back(c);
    new_outputs_.push_back(outputs_[ci]);
  }
  std::swap(contacts_, new_contacts_);
  std::swap(outputs_, new_outputs_);
  std::swap(batches_, new_batches_);
}

void Model::replace_contact_model(std::size_t ci, const ModelProps& props) {
  Contact& c = contacts_[ci];
  retire_dissipation(c); // the old data is dropped at the next compaction
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
  compact(balls.pos), compact(balls.vel), compact(balls.spin), compact(balls.force);
  compact(balls.moment), compact(balls.applied_force), compact(balls.applied_moment);
  compact(balls.disp), compact(balls.radius), compact(balls.mass), compact(balls.inertia);
  compact(balls.density), compact(balls.fixity), compact(balls.group), compact(balls.id);
  compact(balls.clump), compact(balls.body_work), compact(balls.gravity_work);
  compact(balls.damping_work);
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

Eigen::Matrix3d Model::average_stress(double volume) const {
  // sigma = (1/V) sum over balls and their contacts of (x_c - x_b) (x) f, tension positive.
  Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
  for (std::size_t ci = 0; ci < contacts_.size(); ++ci) {
    const Contact& c = contacts_[ci];
    const ContactOutput& o = outputs_[ci];
    s -= (o.xc - balls.pos[static_cast<std::size_t>(c.end1)]) * o.force.transpose();
    if (c.kind == ContactKind::BallBall)
      s += (o.xc - balls.pos[static_cast<std::size_t>(c.end2)]) * o.force.transpose();
  }
  s /= volume;
  return 0.5 * (s + s.transpose());
}

std::size_t Model::active_contact_count() const {
  std::size_t count = 0;
  for (const ContactOutput& o : outputs_)
    if (o.force != Vec3::Zero() || o.moment != Vec3::Zero())
      ++count;
  return count;
}

} // namespace rocklab
