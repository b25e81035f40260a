#include "io/scene.hpp"

#include "contact/model_json.hpp"
#include "io/results.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

namespace rocklab {

namespace {

double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

std::uint8_t parse_dofs(JsonObject& o, const std::string& key, int dim) {
  if (!o.has(key))
    return 0;
  const auto& v = o.raw(key);
  const std::vector<std::string> names =
      dim == 2 ? std::vector<std::string>{"x", "y", "rz"}
               : std::vector<std::string>{"x", "y", "z", "rx", "ry", "rz"};
  std::string allowed;
  for (const auto& n : names)
    allowed += (allowed.empty() ? "\"" : ", \"") + n + "\"";
  allowed += ", or \"all\"";
  auto bit = [&](const std::string& s) -> std::uint8_t {
    if (s == "all")
      return 0x3f;
    static const std::map<std::string, int> dofs{{"x", kX},   {"y", kY},   {"z", kZ},
                                                 {"rx", kRx}, {"ry", kRy}, {"rz", kRz}};
    if (std::find(names.begin(), names.end(), s) == names.end())
      o.fail("fix",
             "value \"" + s + "\" is not a degree of freedom here (allowed: " + allowed + ")");
    return dof_bit(dofs.at(s));
  };
  if (v.is_string())
    return bit(v.get<std::string>());
  if (!v.is_array())
    o.fail(key, "expected an array of DOF names (" + allowed + "), got " + describe(v));
  std::uint8_t mask = 0;
  for (const auto& e : v) {
    if (!e.is_string())
      o.fail(key, "expected DOF names (" + allowed + "), got " + describe(e));
    mask |= bit(e.get<std::string>());
  }
  return mask;
}

std::uint8_t parse_fixity(JsonObject& o, int dim) {
  return parse_dofs(o, "fix", dim);
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
    const double rho = o.number("density", Range::positive(), std::nullopt, "kg/m^3");
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
    const double rho = o.number("density", Range::positive(), std::nullopt, "kg/m^3");
    const int g = m.group_index(o.string("group", "default"));
    const std::size_t i = m.balls.add(dim, id, x, r, rho, g);
    read_ball_motion(o, m, i);
    o.finish();
  }
  for (const auto& [jg, path] : top.array("generate", false)) {
    JsonObject o(*jg, top.file(), path);
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
    const double rho = o.number("density", Range::positive(), std::nullopt, "kg/m^3");
    const std::uint64_t seed = static_cast<std::uint64_t>(
        o.integer("seed", 0, std::numeric_limits<std::int64_t>::max(), 1));
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
      return std::clamp<std::int64_t>(static_cast<std::int64_t>((x[d] - lo[d]) / cell), 0,
                                      nc[d] - 1);
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
      for (std::int64_t z = std::max<std::int64_t>(0, cz - 1);
           ok && z <= std::min(cz + 1, nc[2] - 1); ++z)
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
      throw InputError(top.file() + ": key '" + path + ".count': placed only " +
                       std::to_string(placed) + " of " + std::to_string(count) +
                       " balls without overlap in " + std::to_string(attempts) +
                       " attempts; enlarge the box or lower the count");
  }
  read_clumps(top, m, ids);
  if (m.balls.size() == 0)
    throw InputError(top.file() +
                     ": the scene has no balls (give 'balls', 'generate' or 'clumps')");
}

void read_contact_models(JsonObject& top, Model& m) {
  for (const auto& [jr, path] : top.array("contact_models")) {
    JsonObject o(*jr, top.file(), path);
    ModelRule rule;
    rule.ball_facet = o.choice("between", {"ball-ball", "ball-facet"}) == "ball-facet";
    if (o.has("groups")) {
      const auto& g = o.raw("groups");
      const std::size_t want = rule.ball_facet ? 1 : 2;
      if (!g.is_array() || g.size() < 1 || g.size() > want)
        o.fail("groups",
               std::string("expected ") +
                   (rule.ball_facet ? "[\"group\"]" : "[\"group\"] or [\"group1\", \"group2\"]") +
                   ", got " + describe(g));
      for (const auto& e : g)
        if (!e.is_string())
          o.fail("groups", "expected group names, got " + describe(e));
      rule.group1 = m.group_index(g[0].get<std::string>());
      if (g.size() == 2)
        rule.group2 = m.group_index(g[1].get<std::string>());
    }
    if (o.has("wall")) {
      if (!rule.ball_facet)
        o.fail("wall", "only ball-facet rules name a wall");
      const std::string wname = o.string("wall");
      int found = -1;
      for (std::size_t w = 0; w < m.walls.size(); ++w)
        if (m.walls[w].name == wname)
          found = static_cast<int>(w);
      if (found < 0)
        o.fail("wall", "no wall is named \"" + wname + "\"");
      rule.wall = found;
    }
    const std::string model = o.choice("model", model_names());
    const ModelKind kind = model_kind_of(model);
    if (rule.ball_facet && !model_allows_ball_facet(kind))
      o.fail("model", "the " + model + " model is installed at ball-ball contacts only");
    JsonObject props = o.object("properties");
    if (model_inherits(kind)) {
      rule.inherit = props.boolean("inherit", false);
      if (rule.inherit && rule.ball_facet)
        props.fail("inherit", "walls hold no surface properties; inherit on ball-ball rules only");
    }
    rule.props = read_contact_props(props, model, m.settings.dim);
    o.finish();
    m.rules.push_back(rule);
  }
}

void read_history(JsonObject& top, Scene& s) {
  if (!top.has("history"))
    return;
  JsonObject h = top.object("history");
  s.history_every = h.integer("every", 1, std::numeric_limits<std::int32_t>::max(), 100);
  const Model& m = *s.model;
  // The partitions a column may name: those of results.json's energy record.
  const nlohmann::json energies = energy_json(EnergyLedger{});
  auto is_energy = [&](const std::string& q) {
    return energies.contains(q) && q != "initial_total";
  };
  for (const auto& [jc, path] : h.array("columns")) {
    if (!jc->is_string())
      throw InputError(top.file() + ": key '" + path + "': expected a column name, got " +
                       describe(*jc));
    const std::string name = jc->get<std::string>();
    auto bad = [&](const std::string& why) {
      throw InputError(top.file() + ": key '" + path + "': column \"" + name + "\" " + why);
    };
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (;;) {
      const std::size_t slash = name.find('/', start);
      parts.push_back(name.substr(start, slash - start));
      if (slash == std::string::npos)
        break;
      start = slash + 1;
    }
    HistoryColumn c;
    c.name = name;
    auto parse_id = [&](const std::string& what) {
      std::size_t used = 0;
      std::int64_t id = 0;
      try {
        id = std::stoll(parts[1], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != parts[1].size())
        bad("has a " + what + " id that is not an integer");
      return id;
    };
    auto component = [&](const std::string& comp) {
      static const std::map<std::string, int> comps{{"x", 0}, {"y", 1}, {"z", 2}, {"mag", 3}};
      auto it = comps.find(comp);
      if (it == comps.end())
        bad("has component \"" + comp + "\" (allowed: x, y, z, mag)");
      return it->second;
    };
    if (name == "step")
      c.kind = HistoryColumn::Kind::Step;
    else if (name == "time")
      c.kind = HistoryColumn::Kind::Time;
    else if (name == "timestep")
      c.kind = HistoryColumn::Kind::Timestep;
    else if (name == "contacts")
      c.kind = HistoryColumn::Kind::Contacts;
    else if (name == "active_contacts")
      c.kind = HistoryColumn::Kind::ActiveContacts;
    else if (name == "unbalanced_force_ratio")
      c.kind = HistoryColumn::Kind::Ratio;
    else if (parts[0] == "events" && parts.size() == 2) {
      c.kind = HistoryColumn::Kind::Events;
      c.quantity = parts[1];
      if (c.quantity != "contact_created" && c.quantity != "contact_deleted" &&
          c.quantity != "slip_change" && c.quantity != "bond_break")
        bad("names an unknown event (allowed: contact_created, contact_deleted, slip_change, "
            "bond_break)");
    } else if (parts[0] == "energy" && parts.size() == 2) {
      c.kind = HistoryColumn::Kind::Energy;
      c.quantity = parts[1];
      if (!is_energy(c.quantity))
        bad("names an unknown energy partition");
    } else if (parts[0] == "ball" && parts.size() == 4) {
      c.kind = HistoryColumn::Kind::Ball;
      const std::int64_t id = parse_id("ball");
      auto it = std::find(m.balls.id.begin(), m.balls.id.end(), id);
      if (it == m.balls.id.end())
        bad("names ball id " + parts[1] + ", which does not exist");
      c.index = static_cast<std::size_t>(it - m.balls.id.begin());
      c.quantity = parts[2];
      if (c.quantity != "position" && c.quantity != "velocity" && c.quantity != "spin" &&
          c.quantity != "force" && c.quantity != "moment")
        bad("has quantity \"" + c.quantity +
            "\" (allowed: position, velocity, spin, force, moment)");
      c.component = component(parts[3]);
    } else if (parts[0] == "wall" && parts.size() == 4) {
      c.kind = HistoryColumn::Kind::Wall;
      bool found = false;
      for (std::size_t w = 0; w < m.walls.size(); ++w)
        if (m.walls[w].name == parts[1]) {
          c.index = w;
          found = true;
        }
      if (!found)
        bad("names wall \"" + parts[1] + "\", which does not exist");
      c.quantity = parts[2];
      if (c.quantity != "force" && c.quantity != "moment" && c.quantity != "center")
        bad("has quantity \"" + c.quantity + "\" (allowed: force, moment, center)");
      c.component = component(parts[3]);
    } else if (parts[0] == "group" && parts.size() == 3) {
      c.kind = HistoryColumn::Kind::GroupEnergy;
      auto it = std::find(m.group_names.begin(), m.group_names.end(), parts[1]);
      if (it == m.group_names.end())
        bad("names group \"" + parts[1] + "\", which no ball or clump has");
      c.index = static_cast<std::size_t>(it - m.group_names.begin());
      c.quantity = parts[2];
      if (!is_energy(c.quantity) || c.quantity == "boundary_work" || c.quantity == "balance_error")
        bad("names an energy partition that is not traced per group (allowed: kinetic, "
            "kinetic_translational, kinetic_rotational, strain, bond_strain, body_work, "
            "gravity_work, local_damping, slip, dashpot, plastic, bond_break)");
    } else if (parts[0] == "clump" && parts.size() == 4) {
      c.kind = HistoryColumn::Kind::Clump;
      const std::int64_t id = parse_id("clump");
      auto it = std::find_if(m.clumps.begin(), m.clumps.end(),
                             [&](const Clump& k) { return k.id == id; });
      if (it == m.clumps.end())
        bad("names clump id " + parts[1] + ", which does not exist");
      c.index = static_cast<std::size_t>(it - m.clumps.begin());
      c.quantity = parts[2];
      if (c.quantity != "position" && c.quantity != "velocity" && c.quantity != "spin" &&
          c.quantity != "angular_momentum")
        bad("has quantity \"" + c.quantity +
            "\" (allowed: position, velocity, spin, angular_momentum)");
      c.component = component(parts[3]);
    } else {
      bad("is not known (see docs/scene-format.md: step, time, timestep, contacts, "
          "active_contacts, unbalanced_force_ratio, energy/NAME, events/NAME, "
          "ball/ID/QUANTITY/COMPONENT, wall/NAME/QUANTITY/COMPONENT, group/NAME/PARTITION, "
          "clump/ID/QUANTITY/COMPONENT)");
    }
    s.history.push_back(c);
  }
  h.finish();
}

} // namespace

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

Scene load_scene(const std::string& path) {
  Scene s;
  s.file = path;
  const nlohmann::json j = read_json_file(path);
  JsonObject top(j, path, "");
  s.model = std::make_unique<Model>();
  Model& m = *s.model;
  if (top.has("units") && top.string("units") != "SI")
    top.fail("units", "only \"SI\" is supported (m, kg, s, N, Pa)");
  s.description = top.string("description", "");
  m.settings.dim = static_cast<int>(top.integer("dimension", 2, 3));
  const int dim = m.settings.dim;
  m.settings.gravity = top.vec("gravity", dim, Vec3::Zero());
  m.settings.local_damping = top.number("local_damping", Range::half_open(0, 1), 0.7);
  if (top.has("timestep") && top.raw("timestep").is_string()) {
    if (top.string("timestep") != "auto")
      top.fail("timestep", "expected \"auto\" or a positive number of seconds");
  } else {
    m.settings.timestep = top.number("timestep", Range::positive(), 0.0, "s");
  }
  m.settings.timestep_safety = top.number("timestep_safety", {0, 1, true, false}, 0.8);
  m.settings.margin = top.number("margin", Range::positive(), 0.0, "m");

  read_walls(top, m);
  read_balls(top, m);
  for (const auto& [js, spath] : top.array("surface", false)) {
    JsonObject so(*js, path, spath);
    const std::string group = so.string("group");
    if (std::find(m.group_names.begin(), m.group_names.end(), group) == m.group_names.end())
      so.fail("group", "no ball is in group \"" + group + "\"");
    const std::size_t g = static_cast<std::size_t>(m.group_index(group));
    if (m.surface.size() <= g)
      m.surface.resize(g + 1);
    SurfaceProps& sp = m.surface[g];
    auto opt = [&](const char* key, double& out, const char* unit) {
      if (so.has(key))
        out = so.number(key, Range::non_negative(), std::nullopt, unit);
    };
    opt("kn", sp.kn, "N/m");
    opt("ks", sp.ks, "N/m");
    opt("fric", sp.fric, "");
    opt("sj_kn", sp.sj_kn, "Pa/m");
    opt("sj_ks", sp.sj_ks, "Pa/m");
    opt("sj_fric", sp.sj_fric, "");
    so.finish();
  }
  read_contact_models(top, m);

  std::vector<std::pair<const nlohmann::json*, std::string>> stages;
  if (top.has("run") && top.raw("run").is_array())
    stages = top.array("run");
  else
    stages.emplace_back(&top.raw("run"), "run");
  if (stages.empty())
    top.fail("run", "give at least one stage");
  for (const auto& [js, spath] : stages) {
    JsonObject run(*js, path, spath);
    Stage st;
    st.run.cycles = run.integer("cycles", 1, std::numeric_limits<std::int64_t>::max(), 0);
    st.run.time = run.number("time", Range::positive(), 0.0, "s");
    st.run.ratio = run.number("unbalanced_force_ratio", Range::positive(), 0.0);
    st.run.max_cycles = run.integer("max_cycles", 1, std::numeric_limits<std::int64_t>::max(), 0);
    st.run.check_every = run.integer("check_every", 1, 1'000'000, 10);
    for (const auto& [jc, cpath] : run.array("set", false)) {
      JsonObject ch(*jc, path, cpath);
      BallChange bc;
      const std::int64_t id = ch.integer("ball", 0, std::numeric_limits<std::int32_t>::max());
      auto it = std::find(m.balls.id.begin(), m.balls.id.end(), id);
      if (it == m.balls.id.end())
        ch.fail("ball", "no ball has id " + std::to_string(id));
      bc.index = static_cast<std::size_t>(it - m.balls.id.begin());
      if (ch.has("velocity"))
        bc.velocity = ch.vec("velocity", dim);
      if (ch.has("spin"))
        bc.spin = dim == 2 ? Vec3(0, 0, ch.number("spin", Range::any(), std::nullopt, "rad/s"))
                           : ch.vec("spin", dim);
      bc.fix = parse_fixity(ch, dim);
      bc.free = parse_dofs(ch, "free", dim);
      ch.finish();
      st.set.push_back(bc);
    }
    for (const auto& [jm, mpath] : run.array("methods", false)) {
      JsonObject mo(*jm, path, mpath);
      MethodCall mc;
      const std::string model = mo.choice("model", model_names(ModelUse::Methods));
      mc.model = model_kind_of(model);
      mc.method = mo.choice("method", model_methods(mc.model));
      if (mo.has("gap")) {
        const auto& g = mo.raw("gap");
        if (g.is_number()) {
          mc.gap_hi = g.get<double>();
        } else if (g.is_array() && g.size() == 2 && g[0].is_number() && g[1].is_number() &&
                   g[0].get<double>() <= g[1].get<double>()) {
          mc.gap_lo = g[0].get<double>();
          mc.gap_hi = g[1].get<double>();
        } else {
          mo.fail("gap",
                  "expected a maximum gap or [lo, hi] in m with lo <= hi, got " + describe(g));
        }
      }
      if (mc.model == model_kind<FlatJoint>)
        mc.element = static_cast<int>(mo.integer("element", 0, 1'000'000, 0));
      mo.finish();
      st.methods.push_back(mc);
    }
    run.finish();
    const int stops = (st.run.cycles > 0) + (st.run.time > 0) + (st.run.ratio > 0);
    if (stops != 1)
      throw InputError(path + ": key '" + spath +
                       "': give exactly one of 'cycles', 'time' or 'unbalanced_force_ratio'");
    s.stages.push_back(st);
  }
  read_history(top, s);
  top.finish();
  return s;
}

void EventCounts::add(const std::vector<Event>& events) {
  for (const Event& e : events) {
    switch (e.type) {
    case EventType::ContactCreated:
      ++created;
      break;
    case EventType::ContactDeleted:
      ++deleted;
      break;
    case EventType::SlipChange:
      ++slip_change;
      break;
    case EventType::BondBreak:
      ++bond_break;
      break;
    }
  }
}

double energy_partition(const EnergyLedger& e, const std::string& name) {
  return energy_json(e).at(name).get<double>();
}

double history_value(const Model& m, const HistoryColumn& c, const EnergyLedger& e,
                     const EventCounts& counts, const std::vector<EnergyLedger>& groups) {
  auto comp = [&](const Vec3& v) { return c.component == 3 ? v.norm() : v[c.component]; };
  switch (c.kind) {
  case HistoryColumn::Kind::Step:
    return static_cast<double>(m.step());
  case HistoryColumn::Kind::Time:
    return m.time();
  case HistoryColumn::Kind::Timestep:
    return m.timestep();
  case HistoryColumn::Kind::Contacts:
    return static_cast<double>(m.contacts().size());
  case HistoryColumn::Kind::ActiveContacts:
    return static_cast<double>(m.active_contact_count());
  case HistoryColumn::Kind::Ratio:
    return m.mean_unbalanced_force_ratio();
  case HistoryColumn::Kind::Events:
    if (c.quantity == "contact_created")
      return static_cast<double>(counts.created);
    if (c.quantity == "contact_deleted")
      return static_cast<double>(counts.deleted);
    if (c.quantity == "slip_change")
      return static_cast<double>(counts.slip_change);
    return static_cast<double>(counts.bond_break);
  case HistoryColumn::Kind::Energy:
    return energy_partition(e, c.quantity);
  case HistoryColumn::Kind::GroupEnergy:
    return c.index < groups.size() ? energy_partition(groups[c.index], c.quantity) : 0.0;
  case HistoryColumn::Kind::Clump: {
    const Clump& k = m.clumps[c.index];
    if (c.quantity == "position")
      return comp(k.pos);
    if (c.quantity == "velocity")
      return comp(k.vel);
    if (c.quantity == "spin")
      return comp(k.spin);
    return comp(k.L);
  }
  case HistoryColumn::Kind::Ball: {
    const std::size_t i = c.index;
    const Balls& b = m.balls;
    if (c.quantity == "position")
      return comp(b.pos[i]);
    if (c.quantity == "velocity")
      return comp(b.vel[i]);
    if (c.quantity == "spin")
      return comp(b.spin[i]);
    if (c.quantity == "force")
      return comp(b.force[i]);
    return comp(b.moment[i]);
  }
  case HistoryColumn::Kind::Wall: {
    const Wall& w = m.walls[c.index];
    if (c.quantity == "force")
      return comp(w.force);
    if (c.quantity == "moment")
      return comp(w.moment);
    return comp(w.center);
  }
  }
  return 0;
}

} // namespace rocklab
