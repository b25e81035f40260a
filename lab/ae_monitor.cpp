#include "lab/ae_monitor.hpp"

#include <algorithm>
#include <cmath>

namespace rocklab {

double affine_shear_wave_speed(const Model& m, double volume) {
  if (!(volume > 0))
    return 0;
  const int dim = m.settings.dim;
  const std::vector<std::pair<int, int>> planes =
      dim == 2 ? std::vector<std::pair<int, int>>{{0, 1}}
               : std::vector<std::pair<int, int>>{{0, 1}, {1, 2}, {2, 0}};
  const auto& cs = m.contacts();
  const auto& out = m.contact_outputs();
  double g = 0;
  for (std::size_t i = 0; i < cs.size(); ++i) {
    const Contact& c = cs[i];
    if (c.kind != ContactKind::BallBall)
      continue;
    const Vec3 l = m.balls.pos[static_cast<std::size_t>(c.end2)] -
                   m.balls.pos[static_cast<std::size_t>(c.end1)];
    const double ks = out[i].stiff.k_shear, kn = out[i].stiff.k_tran - ks;
    for (const auto& [a, b] : planes) {
      // A unit engineering shear strain in plane (a, b), imposed on the branch vector.
      Vec3 d = Vec3::Zero();
      d[a] = 0.5 * l[b], d[b] = 0.5 * l[a];
      const Vec3 dn = d.dot(c.n) * c.n;
      const Vec3 f = kn * dn + ks * (d - dn);
      g += 0.5 * (f[a] * l[b] + f[b] * l[a]);
    }
  }
  g /= volume * static_cast<double>(planes.size());
  double mass = 0;
  for (const double x : m.balls.mass)
    mass += x;
  const double rho = mass / volume;
  return g > 0 && rho > 0 ? std::sqrt(g / rho) : 0;
}

double AeMonitor::duration(const Model& m, std::int32_t g1, std::int32_t g2) const {
  if (fixed_duration_ > 0)
    return fixed_duration_;
  double r = m.balls.radius[static_cast<std::size_t>(g1)];
  if (g2 >= 0)
    r = std::max(r, m.balls.radius[static_cast<std::size_t>(g2)]);
  // Hazzard & Young (2000): the rupture runs at half the shear-wave speed; it crosses the larger
  // grain of the crack (diameter 2r).
  return v_s_ > 0 ? 2 * r / (0.5 * v_s_) : 0;
}

void AeMonitor::sum_forces(const Model& m) {
  for (Open& o : open_)
    o.a.setZero(), o.f.setZero();
  const auto& cs = m.contacts();
  const auto& out = m.contact_outputs();
  for (std::size_t i = 0; i < cs.size(); ++i) {
    const Contact& c = cs[i];
    const int e1 = source_[static_cast<std::size_t>(c.end1)];
    const int e2 = c.kind == ContactKind::BallBall ? source_[static_cast<std::size_t>(c.end2)] : -1;
    if (e1 == e2)
      continue; // no source grain, or inside one source: equal and opposite
    // The contact's force on piece 2 is the one piece 1 exerts: a source grain's force on its
    // neighbour is +force as piece 1 and -force as piece 2.
    const ContactOutput& o = out[i];
    if (e1 >= 0) {
      Open& s = open_[static_cast<std::size_t>(slot_[static_cast<std::size_t>(e1)])];
      s.a += o.force * o.xc.transpose(), s.f += o.force;
    }
    if (e2 >= 0) {
      Open& s = open_[static_cast<std::size_t>(slot_[static_cast<std::size_t>(e2)])];
      s.a -= o.force * o.xc.transpose(), s.f -= o.force;
    }
  }
}

void AeMonitor::build_partners(const Model& m) {
  const std::size_t n = m.balls.size();
  partner_begin_.assign(n + 1, 0);
  const auto& cs = m.contacts();
  for (const Contact& c : cs)
    if (c.kind == ContactKind::BallBall)
      ++partner_begin_[static_cast<std::size_t>(c.end1) + 1],
          ++partner_begin_[static_cast<std::size_t>(c.end2) + 1];
  for (std::size_t i = 0; i < n; ++i)
    partner_begin_[i + 1] += partner_begin_[i];
  partners_.resize(static_cast<std::size_t>(partner_begin_[n]));
  std::vector<std::int32_t>& at = partner_fill_;
  at.assign(partner_begin_.begin(), partner_begin_.end() - 1);
  for (const Contact& c : cs)
    if (c.kind == ContactKind::BallBall) {
      partners_[static_cast<std::size_t>(at[static_cast<std::size_t>(c.end1)]++)] = c.end2;
      partners_[static_cast<std::size_t>(at[static_cast<std::size_t>(c.end2)]++)] = c.end1;
    }
}

void AeMonitor::assign(const Model& m, const Crack& c) {
  const ContactEnds ends = contact_ends(c.contact);
  const std::int32_t g1 = ends.end1, g2 = ends.kind == ContactKind::BallBall ? ends.end2 : -1;
  // The open event with the lowest id among those the crack's grains belong to or touch.
  int join = -1;
  auto look = [&](std::int32_t g) {
    const int e = source_[static_cast<std::size_t>(g)];
    if (e >= 0 && (join < 0 || e < join))
      join = e;
  };
  for (const std::int32_t g : {g1, g2}) {
    if (g < 0)
      continue;
    look(g);
    for (std::int32_t k = partner_begin_[static_cast<std::size_t>(g)];
         k < partner_begin_[static_cast<std::size_t>(g) + 1]; ++k)
      look(partners_[static_cast<std::size_t>(k)]);
  }
  if (join < 0) {
    join = static_cast<int>(sources_.size());
    sources_.push_back({});
    slot_.push_back(static_cast<int>(open_.size()));
    open_.push_back({});
    open_.back().event = join; // its sums before it had grains are zero
  }
  event_of_crack_.push_back(join);
  Open& o = open_[static_cast<std::size_t>(slot_[static_cast<std::size_t>(join)])];
  o.end = std::max(o.end, c.time + duration(m, g1, g2));
  o.crack_sum += c.position;
  o.cracks += 1;
  for (const std::int32_t g : {g1, g2})
    if (g >= 0 && source_[static_cast<std::size_t>(g)] < 0) {
      source_[static_cast<std::size_t>(g)] = join; // a grain stays in the first event it joined
      o.grains.push_back(g);
      o.changed = true;
    }
}

void AeMonitor::follow(double time) {
  for (Open& o : open_) {
    const Vec3 centroid = o.crack_sum / std::max(o.cracks, 1);
    const Mat3 mt = (o.a - o.a0) - (o.f - o.f0) * centroid.transpose(); // sum dF_i (x - c)_j
    const Mat3 sym = 0.5 * (mt + mt.transpose());
    // M0 = (sum of squared eigenvalues / 2)^(1/2), and for a symmetric tensor the sum of its
    // squared eigenvalues is its squared Frobenius norm: no eigen-solve per step (the reading
    // is made once, of the kept tensor). In 2D the tensor's z row and column are zero.
    const double m0 = sym.norm() / std::sqrt(2.0);
    AeSource& s = sources_[static_cast<std::size_t>(o.event)];
    s.grains = static_cast<int>(o.grains.size());
    if (m0 > s.m0) {
      s.m0 = m0;
      s.tensor = sym;
      s.time_of_max = time;
    }
  }
}

void AeMonitor::close_ended(double time) {
  bool closed = false;
  for (Open& o : open_)
    if (time > o.end) {
      sources_[static_cast<std::size_t>(o.event)].end = time;
      for (const std::int32_t g : o.grains)
        source_[static_cast<std::size_t>(g)] = -1;
      slot_[static_cast<std::size_t>(o.event)] = -1;
      o.event = -1;
      closed = true;
    }
  if (!closed)
    return;
  open_.erase(std::remove_if(open_.begin(), open_.end(), [](const Open& o) { return o.event < 0; }),
              open_.end());
  for (std::size_t k = 0; k < open_.size(); ++k)
    slot_[static_cast<std::size_t>(open_[k].event)] = static_cast<int>(k);
}

void AeMonitor::step(const Model& m, const std::vector<Crack>& cracks, double volume) {
  const bool fresh = seen_ < cracks.size();
  if (open_.empty() && !fresh)
    return;
  if (source_.size() != m.balls.size()) { // the first call, or the first after a checkpoint
    source_.assign(m.balls.size(), -1);
    for (const Open& o : open_)
      for (const std::int32_t g : o.grains)
        source_[static_cast<std::size_t>(g)] = o.event;
  }
  if (fresh && !(v_s_ > 0))
    v_s_ = affine_shear_wave_speed(m, volume);
  if (!open_.empty() && tensors_)
    sum_forces(m); // the sources as they were before this step's cracks
  if (fresh) {
    for (Open& o : open_)
      o.a_before = o.a, o.f_before = o.f;
    build_partners(m);
    for (; seen_ < cracks.size(); ++seen_)
      assign(m, cracks[seen_]);
    // A source that gained grains is summed again; its baseline moves by the jump, so that its
    // tensor counts only force changes from now on for the new grains' contacts.
    if (tensors_)
      sum_forces(m);
    for (Open& o : open_)
      if (o.changed) {
        o.a0 += o.a - o.a_before, o.f0 += o.f - o.f_before;
        o.changed = false;
      }
  }
  if (tensors_)
    follow(m.time());
  close_ended(m.time());
}

void AeMonitor::finish(double time) {
  for (Open& o : open_)
    o.end = std::min(o.end, time - 1); // every event ends now
  close_ended(time);
}

std::vector<AeSource> AeMonitor::sources() const {
  return sources_;
}

namespace {

nlohmann::json flat(const Mat3& a) {
  return std::vector<double>(a.data(), a.data() + 9);
}
nlohmann::json flat(const Vec3& a) {
  return std::vector<double>{a.x(), a.y(), a.z()};
}
Mat3 mat3(const nlohmann::json& j) {
  Mat3 a;
  for (int k = 0; k < 9; ++k)
    a.data()[k] = j.at(static_cast<std::size_t>(k)).get<double>();
  return a;
}
Vec3 vec3(const nlohmann::json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

} // namespace

nlohmann::json AeMonitor::to_json() const {
  nlohmann::json src = nlohmann::json::array(), open = nlohmann::json::array();
  for (const AeSource& s : sources_)
    src.push_back({{"tensor", flat(s.tensor)},
                   {"m0", s.m0},
                   {"time_of_max", s.time_of_max},
                   {"end", s.end},
                   {"grains", s.grains}});
  for (const Open& o : open_)
    open.push_back({{"event", o.event},
                    {"end", o.end},
                    {"grains", o.grains},
                    {"a0", flat(o.a0)},
                    {"f0", flat(o.f0)},
                    {"crack_sum", flat(o.crack_sum)},
                    {"cracks", o.cracks}});
  return {{"shear_wave_speed", v_s_},
          {"seen", seen_},
          {"event_of_crack", event_of_crack_},
          {"sources", src},
          {"open", open}};
}

void AeMonitor::from_json(const nlohmann::json& j) {
  v_s_ = j.at("shear_wave_speed").get<double>();
  seen_ = j.at("seen").get<std::size_t>();
  event_of_crack_ = j.at("event_of_crack").get<std::vector<int>>();
  sources_.clear();
  for (const auto& s : j.at("sources"))
    sources_.push_back({mat3(s.at("tensor")), s.at("m0").get<double>(),
                        s.at("time_of_max").get<double>(), s.at("end").get<double>(),
                        s.at("grains").get<int>()});
  open_.clear();
  slot_.assign(sources_.size(), -1);
  for (const auto& x : j.at("open")) {
    Open o;
    o.event = x.at("event").get<int>();
    o.end = x.at("end").get<double>();
    o.grains = x.at("grains").get<std::vector<std::int32_t>>();
    o.a0 = mat3(x.at("a0"));
    o.f0 = vec3(x.at("f0"));
    o.crack_sum = vec3(x.at("crack_sum"));
    o.cracks = x.at("cracks").get<int>();
    slot_[static_cast<std::size_t>(o.event)] = static_cast<int>(open_.size());
    open_.push_back(std::move(o));
  }
  source_.clear(); // marked again from the open events at the next step
}

} // namespace rocklab
