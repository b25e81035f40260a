#include "io/scene.hpp"

#include "contact/model_json.hpp"
#include "io/scene_parts.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace rocklab {

namespace scene_detail {

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

} // namespace scene_detail

using namespace scene_detail;

namespace {

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

// Surface properties of groups, inherited by contact rules that ask for it.
void read_surface(JsonObject& top, Model& m) {
  for (const auto& [js, spath] : top.array("surface", false)) {
    JsonObject so(*js, top.file(), spath);
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
}

// Changes to balls at the start of a stage.
void read_ball_changes(JsonObject& run, const Model& m, Stage& st) {
  const int dim = m.settings.dim;
  const std::string& path = run.file();
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
}

// Contact-model methods called at the start of a stage.
void read_methods(JsonObject& run, Stage& st) {
  const std::string& path = run.file();
  for (const auto& [jm, mpath] : run.array("methods", false)) {
    JsonObject mo(*jm, path, mpath);
    MethodCall mc;
    const std::string model = mo.choice("model", model_names(ModelUse::Methods));
    mc.model = model_kind_of(model);
    mc.method = mo.choice("method", model_methods(mc.model));
    if (mo.has("gap") && mo.has("gap_ratio"))
      mo.fail("gap_ratio", "give either 'gap' (m) or 'gap_ratio' (of the radii sum), not both");
    mc.gap_ratio = mo.has("gap_ratio");
    const std::string gkey = mc.gap_ratio ? "gap_ratio" : "gap";
    if (mo.has(gkey)) {
      const auto& g = mo.raw(gkey);
      if (g.is_number()) {
        mc.gap_hi = g.get<double>();
      } else if (g.is_array() && g.size() == 2 && g[0].is_number() && g[1].is_number() &&
                 g[0].get<double>() <= g[1].get<double>()) {
        mc.gap_lo = g[0].get<double>();
        mc.gap_hi = g[1].get<double>();
      } else {
        mo.fail(gkey, std::string("expected a maximum or [lo, hi] with lo <= hi (") +
                          (mc.gap_ratio ? "fractions of R1 + R2" : "m") + "), got " + describe(g));
      }
      if (mc.gap_ratio && !(mc.gap_hi <= 1 && (g.is_number() || mc.gap_lo >= -1)))
        mo.fail(gkey, "a gap ratio lies within [-1, 1] (a gap beyond the radii sum reaches past "
                      "the neighbours), got " +
                          describe(g));
    }
    if (mc.model == model_kind<FlatJoint>)
      mc.element = static_cast<int>(mo.integer("element", 0, 1'000'000, 0));
    mo.finish();
    st.methods.push_back(mc);
  }
}

} // namespace

Scene load_scene(const std::string& path) {
  Scene s;
  s.file = path;
  const nlohmann::json j = read_json_file(path);
  JsonObject top(j, path, "");
  s.model = std::make_unique<Model>();
  Model& m = *s.model;
  s.description = read_header(top, "").description;
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
  m.balls.track_orientation(top.boolean("orientation_tracking", false));

  read_walls(top, m);
  read_balls(top, m);
  // Grains far from spatial order (another code's packing sorted by size, a shuffled list) are
  // renumbered along a Morton curve so that the cycle's threads share few of them; every output
  // names grains by their ids, and ball ids in the rest of the scene are looked up after this.
  m.renumber_spatially();
  read_surface(top, m);
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
    read_ball_changes(run, m, st);
    read_methods(run, st);
    run.finish();
    const int stops = (st.run.cycles > 0) + (st.run.time > 0) + (st.run.ratio > 0);
    if (stops != 1)
      throw InputError(path + ": key '" + spath +
                       "': give exactly one of 'cycles', 'time' or 'unbalanced_force_ratio'");
    s.stages.push_back(st);
  }
  read_history(top, s);
  if (top.has("output")) {
    JsonObject o = top.object("output");
    if (o.has("contacts"))
      s.contacts_output =
          o.boolean("contacts") ? ContactOutputMode::Always : ContactOutputMode::Never;
    o.finish();
  }
  top.finish();
  return s;
}

} // namespace rocklab
