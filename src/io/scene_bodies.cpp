// Scene bodies: walls (facets, planes, boxes), balls (listed or generated without overlap) and
// clumps (pebble lists or templates). Units SI.
#include "io/scene_parts.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <random>

namespace rocklab {

namespace scene_detail {

namespace {

double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

void read_ball_motion(JsonObject& o, Model& m, std::size_t i) {
  const int dim = m.settings.dim;
  m.balls.vel[i] = o.vec("velocity", dim, Vec3::Zero());
  if (dim == 2) {
    m.balls.spin[i] = Vec3(0, 0, o.number("spin", Range::any(), 0.0, "rad/s"));
  } else {
    m.balls.spin[i] = o.vec("spin", dim, Vec3::Zero());
  }
  m.balls.applied_force[i] = o.vec("force", dim, Vec3::Zero());
  if (dim == 2)
    m.balls.applied_moment[i] = Vec3(0, 0, o.number("moment", Range::any(), 0.0, "N m"));
  else
    m.balls.applied_moment[i] = o.vec("moment", dim, Vec3::Zero());
  m.balls.fixity[i] = parse_fixity(o, dim);
}

Facet make_facet(const std::vector<Vec3>& pts) {
  Facet f;
  f.nv = static_cast<int>(pts.size());
  for (std::size_t k = 0; k < pts.size(); ++k)
    f.v[k] = pts[k];
  return f;
}

} // namespace

void read_walls(JsonObject& top, Model& m) {
  const int dim = m.settings.dim;
  for (const auto& [jw, path] : top.array("walls", false)) {
    JsonObject o(*jw, top.file(), path);
    const std::string name = o.string("name");
    for (const Wall& w : m.walls)
      if (w.name == name || w.name.rfind(name + ".", 0) == 0)
        o.fail("name", "value \"" + name + "\" is used by another wall; names must be unique");
    std::vector<Wall> made;
    const int shapes = o.has("facets") + o.has("plane") + o.has("box");
    if (shapes != 1)
      throw InputError(top.file() + ": key '" + path +
                       "': give exactly one of 'facets', 'plane' or 'box'");
    if (o.has("facets")) {
      Wall w;
      w.name = name;
      for (const auto& [jf, fpath] : o.array("facets")) {
        if (!jf->is_array() || jf->size() != static_cast<std::size_t>(dim))
          throw InputError(top.file() + ": key '" + fpath + "': expected " +
                           (dim == 2 ? "a segment of 2 points" : "a triangle of 3 points") +
                           ", got " + describe(*jf));
        std::vector<Vec3> pts;
        for (std::size_t k = 0; k < jf->size(); ++k)
          pts.push_back(json_vec((*jf)[k], dim, top.file(), fpath + "[" + std::to_string(k) + "]"));
        w.facets.push_back(make_facet(pts));
      }
      if (w.facets.empty())
        o.fail("facets", "a wall needs at least one facet");
      made.push_back(std::move(w));
    } else if (o.has("plane")) {
      JsonObject p = o.object("plane");
      const Vec3 point = p.vec("point", dim);
      Vec3 n = p.vec("normal", dim);
      if (n.norm() == 0)
        p.fail("normal", "the normal must not be the zero vector");
      n.normalize();
      const double extent = p.number("extent", Range::positive(), std::nullopt, "m");
      p.finish();
      Wall w;
      w.name = name;
      w.facets = plane_wall(dim, name, point, n, extent).facets;
      made.push_back(std::move(w));
    } else {
      JsonObject b = o.object("box");
      const Vec3 lo = b.vec("min", dim), hi = b.vec("max", dim);
      for (int d = 0; d < dim; ++d)
        if (!(hi[d] > lo[d]))
          b.fail("max", "each component must exceed the one of 'min'");
      b.finish();
      const Vec3 mid = 0.5 * (lo + hi);
      const Vec3 size = hi - lo;
      const char* axis[3] = {"x", "y", "z"};
      for (int d = 0; d < dim; ++d)
        for (int side = 0; side < 2; ++side) {
          Vec3 p = mid;
          p[d] = side ? hi[d] : lo[d];
          Vec3 n = Vec3::Zero();
          n[d] = 1;
          const double extent = 1.2 * size.maxCoeff();
          Wall w;
          w.name = name + "." + axis[d] + (side ? "max" : "min");
          w.facets = plane_wall(dim, w.name, p, n, extent).facets;
          made.push_back(std::move(w));
        }
    }
    const Vec3 vel = o.vec("velocity", dim, Vec3::Zero());
    Vec3 spin = Vec3::Zero();
    if (dim == 2)
      spin.z() = o.number("spin", Range::any(), 0.0, "rad/s");
    else
      spin = o.vec("spin", dim, Vec3::Zero());
    std::optional<Vec3> center;
    if (o.has("center"))
      center = o.vec("center", dim);
    o.finish();
    for (Wall& w : made) {
      w.velocity = vel;
      w.spin = spin;
      if (center) {
        w.center = *center;
      } else {
        Vec3 c = Vec3::Zero();
        int count = 0;
        for (const Facet& f : w.facets)
          for (int k = 0; k < f.nv; ++k, ++count)
            c += f.v[k];
        w.center = c / count;
      }
      w.update_bounds();
      m.walls.push_back(std::move(w));
    }
  }
}

namespace {

// Clumps: explicit pebbles (global positions) or a template placed by the centroid of its
// pebble centres, scaled by a pebble radius and turned (2D: degrees about z; 3D: a rotation
// vector in degrees). Pebble ids continue after the largest ball id.
void read_clumps(JsonObject& top, Model& m, std::map<std::int64_t, std::string>& ids) {
  const int dim = m.settings.dim;
  std::int64_t next_id = 1;
  for (const auto& [id, where] : ids)
    next_id = std::max(next_id, id + 1);
  std::map<std::int64_t, std::string> clump_ids;
  for (const auto& [jc, path] : top.array("clumps", false)) {
    JsonObject o(*jc, top.file(), path);
    const std::int64_t id = o.integer("id", 0, std::numeric_limits<std::int32_t>::max(),
                                      static_cast<std::int64_t>(m.clumps.size()) + 1);
    if (auto [it, fresh] = clump_ids.emplace(id, path); !fresh)
      o.fail("id", std::to_string(id) + " is already used by " + it->second);
    const double rho = o.number("density", Range::density(), std::nullopt, "kg/m^3");
    const int g = m.group_index(o.string("group", "default"));
    const std::vector<Pebble> pebbles = read_clump_pebbles(o, dim, true);
    const Vec3 vel = o.vec("velocity", dim, Vec3::Zero());
    const Vec3 spin = dim == 2 ? Vec3(0, 0, o.number("spin", Range::any(), 0.0, "rad/s"))
                               : o.vec("spin", dim, Vec3::Zero());
    for (std::size_t k = 0; k < pebbles.size(); ++k)
      ids.emplace(next_id + static_cast<std::int64_t>(k), path + ".pebbles");
    const std::size_t index = m.add_clump(pebbles, rho, g, id, next_id, vel, spin);
    next_id += static_cast<std::int64_t>(pebbles.size());
    Clump& c = m.clumps[index];
    c.applied_force = o.vec("force", dim, Vec3::Zero());
    c.applied_moment = dim == 2 ? Vec3(0, 0, o.number("moment", Range::any(), 0.0, "N m"))
                                : o.vec("moment", dim, Vec3::Zero());
    o.finish();
  }
}

} // namespace

namespace {

// One 'generate' entry: balls of uniformly distributed radii placed at random without overlap
// (random sequential insertion with a cell grid for the overlap test).
void generate_balls(JsonObject& o, const std::string& path, Model& m,
                    std::map<std::int64_t, std::string>& ids,
                    const std::function<void(std::int64_t, const std::string&)>& claim_id) {
  const int dim = m.settings.dim;
  const std::string file = o.file();
  const std::int64_t count = o.integer("count", 1, 10'000'000);
  const auto& jr = o.raw("radius");
  if (!jr.is_array() || jr.size() != 2 || !jr[0].is_number() || !jr[1].is_number())
    o.fail("radius", "expected [R_min, R_max] in metres, got " + describe(jr));
  const double rmin = jr[0].get<double>(), rmax = jr[1].get<double>();
  if (!(rmin > 0) || rmax < rmin)
    o.fail("radius", "value " + jr.dump() + " must satisfy 0 < R_min <= R_max");
  JsonObject box = o.object("box");
  const Vec3 lo = box.vec("min", dim), hi = box.vec("max", dim);
  box.finish();
  for (int d = 0; d < dim; ++d)
    if (!(hi[d] - lo[d] > 2 * rmax))
      o.fail("box", "the box must be wider than 2 R_max along every axis");
  const double rho = o.number("density", Range::density(), std::nullopt, "kg/m^3");
  const std::uint64_t seed =
      static_cast<std::uint64_t>(o.integer("seed", 0, std::numeric_limits<std::int64_t>::max(), 1));
  const int g = m.group_index(o.string("group", "default"));
  std::int64_t next_id = o.integer("first_id", 0, std::numeric_limits<std::int32_t>::max(),
                                   static_cast<std::int64_t>(m.balls.size()) + 1);
  const std::int64_t attempts = o.integer("attempts", 1, 1'000'000'000, 1000 * count);
  o.finish();
  // Random sequential insertion without overlap, with a cell grid for the overlap test.
  std::mt19937_64 rng(seed);
  const double cell = 2 * rmax;
  std::array<std::int64_t, 3> nc{1, 1, 1};
  for (int d = 0; d < dim; ++d)
    nc[d] = std::max<std::int64_t>(1, static_cast<std::int64_t>((hi[d] - lo[d]) / cell));
  std::vector<std::vector<std::size_t>> grid(static_cast<std::size_t>(nc[0] * nc[1] * nc[2]));
  auto cell_of = [&](const Vec3& x, int d) {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>((x[d] - lo[d]) / cell), 0, nc[d] - 1);
  };
  std::int64_t placed = 0, tried = 0;
  while (placed < count && tried < attempts) {
    ++tried;
    const double r = rmin + (rmax - rmin) * uniform01(rng);
    Vec3 x = Vec3::Zero();
    for (int d = 0; d < dim; ++d)
      x[d] = lo[d] + r + (hi[d] - lo[d] - 2 * r) * uniform01(rng);
    const std::int64_t cx = cell_of(x, 0), cy = cell_of(x, 1), cz = dim == 3 ? cell_of(x, 2) : 0;
    bool ok = true;
    for (std::int64_t z = std::max<std::int64_t>(0, cz - 1); ok && z <= std::min(cz + 1, nc[2] - 1);
         ++z)
      for (std::int64_t y = std::max<std::int64_t>(0, cy - 1);
           ok && y <= std::min(cy + 1, nc[1] - 1); ++y)
        for (std::int64_t xx = std::max<std::int64_t>(0, cx - 1);
             ok && xx <= std::min(cx + 1, nc[0] - 1); ++xx)
          for (std::size_t j : grid[static_cast<std::size_t>((z * nc[1] + y) * nc[0] + xx)]) {
            const double rr = r + m.balls.radius[j];
            if ((m.balls.pos[j] - x).squaredNorm() < rr * rr) {
              ok = false;
              break;
            }
          }
    if (!ok)
      continue;
    while (ids.count(next_id))
      ++next_id;
    claim_id(next_id, path);
    const std::size_t i = m.balls.add(dim, next_id++, x, r, rho, g);
    grid[static_cast<std::size_t>((cz * nc[1] + cy) * nc[0] + cx)].push_back(i);
    ++placed;
  }
  if (placed < count)
    throw InputError(file + ": key '" + path + ".count': placed only " + std::to_string(placed) +
                     " of " + std::to_string(count) + " balls without overlap in " +
                     std::to_string(attempts) + " attempts; enlarge the box or lower the count");
}

} // namespace

void read_balls(JsonObject& top, Model& m) {
  const int dim = m.settings.dim;
  std::map<std::int64_t, std::string> ids;
  auto claim_id = [&](std::int64_t id, const std::string& where) {
    auto [it, fresh] = ids.emplace(id, where);
    if (!fresh)
      throw InputError(top.file() + ": key '" + where + ".id': value " + std::to_string(id) +
                       " is already used by " + it->second + "; ball ids must be unique");
  };
  for (const auto& [jb, path] : top.array("balls", false)) {
    JsonObject o(*jb, top.file(), path);
    const std::int64_t id = o.integer("id", 0, std::numeric_limits<std::int32_t>::max(),
                                      static_cast<std::int64_t>(m.balls.size()) + 1);
    claim_id(id, path);
    const Vec3 x = o.vec("position", dim);
    const double r = o.number("radius", Range::positive(), std::nullopt, "m");
    const double rho = o.number("density", Range::density(), std::nullopt, "kg/m^3");
    const int g = m.group_index(o.string("group", "default"));
    const std::size_t i = m.balls.add(dim, id, x, r, rho, g);
    read_ball_motion(o, m, i);
    o.finish();
  }
  for (const auto& [jg, path] : top.array("generate", false)) {
    JsonObject o(*jg, top.file(), path);
    generate_balls(o, path, m, ids, claim_id);
  }
  read_clumps(top, m, ids);
  if (m.balls.size() == 0)
    throw InputError(top.file() +
                     ": the scene has no balls (give 'balls', 'generate' or 'clumps')");
}

} // namespace scene_detail

std::vector<Pebble> read_clump_pebbles(JsonObject& o, int dim, bool position_required) {
  std::vector<Pebble> pebbles;
  if (o.has("pebbles") == o.has("template"))
    o.fail(o.has("pebbles") ? "template" : "pebbles",
           "give either 'pebbles' (a list) or 'template' (a name), exactly one");
  if (o.has("pebbles")) {
    for (const auto& [jp, ppath] : o.array("pebbles")) {
      JsonObject po(*jp, o.file(), ppath);
      pebbles.push_back(
          {po.vec("position", dim), po.number("radius", Range::positive(), std::nullopt, "m")});
      po.finish();
    }
    if (pebbles.empty())
      o.fail("pebbles", "give at least one pebble");
  } else {
    const std::string name =
        o.choice("template", {"single", "pair", "line3", "triangle3", "tetra4"});
    if (dim == 2 && name == "tetra4")
      o.fail("template", "\"tetra4\" is a 3D template");
    const double r = o.number("radius", Range::positive(), std::nullopt, "m");
    const Vec3 at =
        position_required ? o.vec("position", dim) : o.vec("position", dim, Vec3::Zero());
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    constexpr double deg = 3.14159265358979323846 / 180.0;
    if (dim == 2) {
      R = Eigen::AngleAxisd(o.number("rotation", Range::any(), 0.0, "deg") * deg, Vec3::UnitZ())
              .toRotationMatrix();
    } else {
      const Vec3 phi = o.vec("rotation", dim, Vec3::Zero()) * deg;
      if (phi.norm() > 0)
        R = Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix();
    }
    for (const Pebble& p : clump_template(name, dim))
      pebbles.push_back({at + R * (p.position * r), r});
  }
  return pebbles;
}

} // namespace rocklab
