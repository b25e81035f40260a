#include "materials/material_card.hpp"

#include "io/json_input.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

namespace rocklab {

double ShapeSpec::volume(int dim) const {
  // A disk's face: the circle less the two circular segments of angle 2a the flats cut off.
  const double face =
      0.25 * size.x() * size.x() * (std::numbers::pi - (flat_angle - std::sin(flat_angle)));
  switch (shape) {
  case SpecimenShape::Rectangle:
    return size.x() * size.y();
  case SpecimenShape::Disk2D:
    return face;
  case SpecimenShape::Prism:
    return size.x() * size.y() * size.z();
  case SpecimenShape::Cylinder:
  case SpecimenShape::Disk3D:
    return face * size.y();
  }
  (void)dim;
  return 0;
}

bool ShapeSpec::contains(const Vec3& x, double m) const {
  switch (shape) {
  case SpecimenShape::Rectangle:
    return std::abs(x.x()) <= 0.5 * size.x() - m && std::abs(x.y()) <= 0.5 * size.y() - m;
  case SpecimenShape::Disk2D:
    return std::hypot(x.x(), x.y()) <= 0.5 * size.x() - m && within_flats(x, m);
  case SpecimenShape::Prism:
    return std::abs(x.x()) <= 0.5 * size.x() - m && std::abs(x.y()) <= 0.5 * size.y() - m &&
           std::abs(x.z()) <= 0.5 * size.z() - m;
  case SpecimenShape::Cylinder:
  case SpecimenShape::Disk3D:
    return std::hypot(x.x(), x.y()) <= 0.5 * size.x() - m &&
           std::abs(x.z()) <= 0.5 * size.y() - m && within_flats(x, m);
  }
  return false;
}

bool ShapeSpec::within_flats(const Vec3& x, double m) const {
  return flat_angle <= 0 || std::abs(x.y()) <= 0.5 * size.x() * std::cos(0.5 * flat_angle) - m;
}

namespace {

ShapeSpec read_shape(JsonObject o, int dim, bool cut) {
  ShapeSpec s;
  const std::string shape = dim == 2 ? o.choice("shape", {"rectangle", "disk"})
                                     : o.choice("shape", {"prism", "cylinder", "disk"});
  const Range pos = Range::positive();
  if (shape == "rectangle") {
    s.shape = SpecimenShape::Rectangle;
    s.size = Vec3(o.number("width", pos, std::nullopt, "m"),
                  o.number("height", pos, std::nullopt, "m"), 0);
  } else if (shape == "disk" && dim == 2) {
    s.shape = SpecimenShape::Disk2D;
    s.size = Vec3(o.number("diameter", pos, std::nullopt, "m"), 0, 0);
  } else if (shape == "prism") {
    s.shape = SpecimenShape::Prism;
    s.size = o.vec("size", 3, std::nullopt, Range::positive());
  } else if (shape == "cylinder") {
    s.shape = SpecimenShape::Cylinder;
    s.size = Vec3(o.number("diameter", pos, std::nullopt, "m"),
                  o.number("height", pos, std::nullopt, "m"), 0);
  } else {
    s.shape = SpecimenShape::Disk3D;
    s.size = Vec3(o.number("diameter", pos, std::nullopt, "m"),
                  o.number("thickness", pos, std::nullopt, "m"), 0);
  }
  if (shape == "disk" && cut) // a flattened Brazilian disk (docs/material-format.md)
    s.flat_angle =
        o.number("flat_angle", Range::closed(0, 60), 0.0, "deg") * std::numbers::pi / 180;
  else if (o.has("flat_angle"))
    o.fail("flat_angle", shape == "disk" ? "flats are cut: they apply to a disk under 'cut' (cut "
                                           "from a block), not to a vessel"
                                         : "applies to a disk only");
  o.finish();
  return s;
}

} // namespace

nlohmann::json shape_json(const ShapeSpec& s, int dim) {
  nlohmann::json j;
  switch (s.shape) {
  case SpecimenShape::Rectangle:
    return {{"shape", "rectangle"}, {"width", s.size.x()}, {"height", s.size.y()}};
  case SpecimenShape::Prism:
    return {{"shape", "prism"}, {"size", {s.size.x(), s.size.y(), s.size.z()}}};
  case SpecimenShape::Cylinder:
    return {{"shape", "cylinder"}, {"diameter", s.size.x()}, {"height", s.size.y()}};
  case SpecimenShape::Disk2D:
    j = {{"shape", "disk"}, {"diameter", s.size.x()}};
    break;
  case SpecimenShape::Disk3D:
    j = {{"shape", "disk"}, {"diameter", s.size.x()}, {"thickness", s.size.y()}};
    break;
  }
  if (s.flat_angle > 0) // in degrees as a card gives it, rounded back from radians
    j["flat_angle"] = std::round(s.flat_angle * 180 / std::numbers::pi * 1e9) / 1e9;
  (void)dim;
  return j;
}

ShapeSpec shape_from_json(const nlohmann::json& j, int dim, const std::string& file,
                          const std::string& key, bool cut) {
  return read_shape(JsonObject(j, file, key), dim, cut);
}

void apply_overrides(MaterialCard& card, const GenesisOverrides& o) {
  if (!o.shape.value.is_null()) {
    card.vessel = shape_from_json(o.shape.value, card.dim, o.shape.file, o.shape.key);
    card.vessel_file = o.shape.file, card.vessel_key = o.shape.key;
  }
  if (!o.cut.value.is_null())
    card.cut = shape_from_json(o.cut.value, card.dim, o.cut.file, o.cut.key, true);
  if (o.seed)
    card.seed = *o.seed;
}

namespace {

void read_grains(JsonObject& top, MaterialCard& c) {
  JsonObject g = top.object("grains");
  if (g.has("radius") == g.has("sieve"))
    top.fail("grains", "give exactly one of 'radius' [R_min, R_max] or 'sieve'");
  if (g.has("radius")) {
    const auto& r = g.raw("radius");
    if (!r.is_array() || r.size() != 2 || !r[0].is_number() || !r[1].is_number())
      g.fail("radius", "expected [R_min, R_max] in m, got " + describe(r));
    c.r_min = r[0].get<double>();
    c.r_max = r[1].get<double>();
    if (!(c.r_min > 0))
      g.fail("radius", "R_min = " + r[0].dump() + " is out of range (0, +inf) m");
    if (c.r_min > c.r_max)
      g.fail("radius", "R_min = " + r[0].dump() + " exceeds R_max = " + r[1].dump());
  } else {
    const auto& sv = g.raw("sieve");
    if (!sv.is_array() || sv.size() < 2)
      g.fail("sieve", "expected at least two [diameter m, fraction passing] pairs");
    double last_d = 0, last_f = 0;
    for (const auto& e : sv) {
      if (!e.is_array() || e.size() != 2 || !e[0].is_number() || !e[1].is_number())
        g.fail("sieve", "expected [diameter m, fraction passing] pairs, got " + describe(e));
      const double d = e[0].get<double>(), f = e[1].get<double>();
      if (!(d > last_d) || f < last_f || f > 1)
        g.fail("sieve", "diameters must increase and fractions passing rise within [0, 1]");
      c.sieve.emplace_back(d, f);
      last_d = d;
      last_f = f;
    }
    if (c.sieve.front().second != 0 || c.sieve.back().second != 1)
      g.fail("sieve", "the curve must start at fraction 0 and end at fraction 1");
    c.r_min = 0.5 * c.sieve.front().first;
    c.r_max = 0.5 * c.sieve.back().first;
  }
  g.finish();
}

void read_packing(JsonObject& top, MaterialCard& c) {
  JsonObject p = top.optional_object("packing");
  c.packing_method = p.choice("method", {"contraction", "scaling"}, "contraction") == "scaling"
                         ? MaterialCard::Packing::Scaling
                         : MaterialCard::Packing::Contraction;
  c.packing_friction = p.number("friction", Range::non_negative(), 0.5);
  c.porosity_tolerance = p.number("porosity_tolerance", {0, 0.1, true, false}, 0.003);
  c.compaction_strain = p.number("compaction_strain", {0, 0.01, true, false}, 5e-4);
  c.cloud_porosity = p.number("cloud_porosity", {0, 1, true, true},
                              std::min(c.porosity + 0.1, 0.5 * (1 + c.porosity)));
  if (c.cloud_porosity <= c.porosity)
    p.fail("cloud_porosity", "must exceed the target porosity " + std::to_string(c.porosity));
  c.max_overlap_ratio = p.number("max_overlap_ratio", Range::positive(), 0.25);
  c.packing_margin_ratio = p.number("margin_ratio", {0, 1, true, false}, 0.0);
  c.equilibrium_ratio = p.number("equilibrium_ratio", Range::positive(), 5e-3);
  c.max_cycles = p.integer("max_cycles", 1000, std::numeric_limits<std::int64_t>::max(), 2'000'000);
  c.eliminate_floaters = p.boolean("eliminate_floaters", false);
  if (p.has("import")) {
    const std::filesystem::path f = p.string("import");
    c.packing_import =
        (f.is_absolute() ? f : std::filesystem::path(c.file).parent_path() / f).string();
    if (!std::filesystem::is_regular_file(c.packing_import))
      p.fail("import", "no such packing file: " + c.packing_import);
    std::ifstream in(c.packing_import, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    c.text_hash = text_hash(c.text_hash + text_hash(ss.str())); // the packing is input too
  }
  p.finish();
}

void read_installation(JsonObject& top, MaterialCard& c) {
  JsonObject i = top.optional_object("installation");
  c.pressure = i.number("pressure", Range::positive(), 1e5, "Pa");
  c.pressure_tolerance = i.number("pressure_tolerance", {0, 1, true, true}, 0.02);
  if (i.has("gap") && i.has("gap_ratio"))
    i.fail("gap", "give either 'gap' (m) or 'gap_ratio' (g_i / R_avg), not both");
  if (i.has("gap_ratio")) {
    c.install_gap_ratio = i.number("gap_ratio", Range::non_negative(), std::nullopt);
    c.install_gap = c.install_gap_ratio * 0.5 * (c.r_min + c.r_max);
  } else
    c.install_gap = i.number("gap", Range::non_negative(), 0.0, "m");
  c.residual_tolerance = i.number("residual_tolerance", Range::positive(), 0.05);
  c.per_contact_draws = i.choice("draws", {"sequence", "per_contact"}, "sequence") == "per_contact";
  c.stiffness_ramp = i.integer("stiffness_ramp", 0, 1'000'000, 0);
  i.finish();
}

// The card's bonded model: the one registered model whose card section the card gives (or none).
void read_bonding(JsonObject& top, MaterialCard& c) {
  std::vector<std::string> all, given;
  for_each_model([&]<class M>() {
    if constexpr (BondsCards<M>) {
      all.emplace_back(M::card_section);
      if (top.has(all.back()))
        given.push_back(all.back());
    }
  });
  if (given.size() > 1) {
    std::string list;
    for (const auto& s : all)
      list += (list.empty() ? "'" : ", '") + s + "'";
    top.fail(given[1], "give one bonded model (" + list + "), not both '" + given[0] + "' and '" +
                           given[1] + "'");
  }
  for_each_model([&]<class M>() {
    if constexpr (BondsCards<M>)
      if (!given.empty() && given[0] == M::card_section)
        c.bonding = M::card_bonding(top, c.dim);
  });
}

void read_joints(JsonObject& top, MaterialCard& c, const std::string& path) {
  for (const auto& [jj, jpath] : top.array("joints", false)) {
    JsonObject j(*jj, path, jpath);
    JointSpec js;
    js.point = j.vec("point", c.dim, Vec3::Zero());
    js.dip = j.number("dip", Range::closed(0, 360), std::nullopt, "deg");
    js.ddir = c.dim == 3 ? j.number("ddir", Range::closed(0, 360), 0.0, "deg") : 0.0;
    js.spacing = j.number("spacing", Range::non_negative(), 0.0, "m");
    js.props.sj_kn = j.number("sj_kn", Range::non_negative(), std::nullopt, "Pa/m");
    js.props.sj_ks = j.number("sj_ks", Range::non_negative(), std::nullopt, "Pa/m");
    js.props.sj_fric = j.number("sj_fric", Range::non_negative(), 0.0);
    js.props.sj_da = j.number("sj_da", Range::half_open(0, 90), 0.0, "deg");
    js.props.bond = j.boolean("bonded", false);
    js.props.bond_gap_hi = 1e300; // the joint replaces existing contacts whatever their gap
    js.props.sj_ten = j.number("sj_ten", Range::non_negative(), 0.0, "Pa");
    js.props.sj_coh = j.number("sj_coh", Range::non_negative(), 0.0, "Pa");
    js.props.sj_fa = j.number("sj_fa", Range::half_open(0, 90), 0.0, "deg");
    js.props.dip = js.dip;
    js.props.ddir = js.ddir;
    j.finish();
    c.joints.push_back(js);
  }
}

} // namespace

MaterialCard load_material_card(const std::string& path) {
  MaterialCard c;
  c.file = path;
  c.text_hash = text_hash(read_input_text(path));
  c.raw = read_json_file(path);
  JsonObject top(c.raw, path, "");
  c.name = read_header(top, std::nullopt).name;
  c.source = top.string("source", "");
  c.dim = static_cast<int>(top.integer("dimension", 2, 3));
  c.density = top.number("density", Range::density(), std::nullopt, "kg/m^3");
  c.seed = static_cast<std::uint64_t>(
      top.integer("seed", 0, std::numeric_limits<std::int64_t>::max(), 1));
  read_grains(top, c);
  c.porosity = top.number("porosity", {0, 1, true, true}, std::nullopt);
  c.vessel = read_shape(top.object("specimen"), c.dim, false);
  if (top.has("cut"))
    c.cut = read_shape(top.object("cut"), c.dim, true);
  if (top.has("clumps")) {
    JsonObject k = top.object("clumps");
    c.clump_max = static_cast<int>(k.integer("max_pebbles", 2, 8));
    if (c.cut)
      k.fail("max_pebbles", "clumped grains cannot be cut from a block (a cut would split "
                            "clumps); leave out 'cut'");
    k.finish();
  }
  read_packing(top, c);
  read_installation(top, c);
  if (!c.packing_import.empty() && c.clump_max > 0)
    top.fail("clumps", "clumped grains are made by packing; they cannot be combined with an "
                       "imported packing ('packing.import')");
  c.linear = read_card_section<Linear>(top, "linear", c.dim, "", {});
  read_bonding(top, c);
  read_joints(top, c, path);
  top.finish();
  return c;
}

} // namespace rocklab
