#include "lab/calibration/calibration_file.hpp"

#include "io/input_error.hpp"
#include "io/json_input.hpp"
#include "io/results.hpp"
#include "lab/frame/frame_test.hpp"
#include "lab/protocol.hpp"
#include "lab/protocol_table.hpp"
#include "materials/material_card.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

namespace fs = std::filesystem;

namespace rocklab::calibration {

// The targets a calibration can aim at: the suite properties the frame tests declare, in the
// protocol table's order (adding a property = the test that measures it).
const std::vector<TargetNeed>& target_needs() {
  static const std::vector<TargetNeed> needs = [] {
    std::vector<TargetNeed> n;
    for (const std::string& name : frame_test_names()) {
      const std::unique_ptr<FrameTest> test = make_frame_test(name);
      for (const SuiteProperty& p : test->suite_properties()) // name(): a literal, it outlives test
        n.push_back({p.name, test->name(), p.count, p.other});
    }
    return n;
  }();
  return needs;
}

namespace {

// The card value at "section.key": a number, or the mean of a {"mean", "sd"} distribution.
const nlohmann::json* card_value(const nlohmann::json& card, const std::string& path) {
  const nlohmann::json* v = &card;
  std::size_t a = 0;
  while (a <= path.size()) {
    const std::size_t b = std::min(path.find('.', a), path.size());
    const std::string part = path.substr(a, b - a);
    if (!v->is_object() || !v->contains(part))
      return nullptr;
    v = &(*v)[part];
    a = b + 1;
  }
  return v;
}

// The card entry at "section.key", for writing.
nlohmann::json& value_at(nlohmann::json& card, const std::string& path) {
  nlohmann::json* v = &card;
  for (std::size_t a = 0; a <= path.size();) {
    const std::size_t b = std::min(path.find('.', a), path.size());
    v = &(*v)[path.substr(a, b - a)];
    a = b + 1;
  }
  return *v;
}

double number_of(const nlohmann::json& v) {
  if (v.is_number())
    return v.get<double>();
  if (v.is_object() && v.contains("mean") && v["mean"].is_number())
    return v["mean"].get<double>();
  return std::nan("");
}

Role role_of(JsonObject& o) {
  const std::string r = o.choice("role", {"modulus", "stiffness_ratio", "strength", "shape"});
  return r == "modulus"           ? Role::Modulus
         : r == "stiffness_ratio" ? Role::StiffnessRatio
         : r == "strength"        ? Role::Strength
                                  : Role::Shape;
}

// "flatjoint.types" for "flatjoint.types.slit" or "flatjoint.types.gapped", else "".
std::string fraction_parent(const std::string& path) {
  for (const std::string leaf : {".types.slit", ".types.gapped"})
    if (path.size() > leaf.size() && path.ends_with(leaf))
      return path.substr(0, path.rfind('.'));
  return "";
}

CardParam read_param(const CalibrationFile& c, JsonObject& top, const std::string& key) {
  JsonObject o = top.object(key);
  CardParam p;
  p.key = key;
  const std::size_t slash = key.find('/');
  p.path = key.substr(0, slash);
  p.over = slash == std::string::npos ? "" : key.substr(slash + 1);
  p.param.name = key;
  p.param.role = role_of(o);
  const auto bounds = o.array("bounds");
  if (bounds.size() != 2 || !bounds[0].first->is_number() || !bounds[1].first->is_number())
    top.fail(key, "\"bounds\" must be [low, high], two numbers");
  p.param.lo = bounds[0].first->get<double>();
  p.param.hi = bounds[1].first->get<double>();
  if (!(p.param.lo < p.param.hi))
    top.fail(key, "empty bounds [" + format_double(p.param.lo) + ", " + format_double(p.param.hi) +
                      "]: low must be below high");
  o.finish();
  double start = std::nan("");
  if (p.path.empty() || (slash != std::string::npos && p.over.empty()))
    top.fail(key, "a parameter is \"section.key\" or a ratio \"section.key/section.key\" "
                  "(e.g. \"flatjoint.fj_coh/flatjoint.fj_ten\"), with no empty side");
  for (const std::string& path : {p.path, p.over}) {
    if (path.empty())
      continue; // not a ratio
    const nlohmann::json* v = card_value(c.material, path);
    if (!v || !std::isfinite(number_of(*v)))
      top.fail(key, "the card " + c.material_file + " has no number or {\"mean\", \"sd\"} at \"" +
                        path + "\" (write \"section.key\", e.g. \"flatjoint.fj_ten\")");
  }
  start = number_of(*card_value(c.material, p.path));
  if (!p.over.empty())
    start /= number_of(*card_value(c.material, p.over));
  if (!(start >= p.param.lo && start <= p.param.hi))
    top.fail(key, "the card's value " + format_double(start) + " lies outside the bounds [" +
                      format_double(p.param.lo) + ", " + format_double(p.param.hi) + "]");
  p.param.value = start;
  if (const std::string types = fraction_parent(p.path); !types.empty()) {
    // The bonded fraction takes the remainder, so it must stay >= 0 over the whole box.
    const nlohmann::json& t = *card_value(c.material, types);
    const bool slit = p.path.ends_with(".slit");
    const double other = t.value(slit ? "gapped" : "slit", 0.0);
    if (!p.over.empty() || p.param.lo < 0 || p.param.hi + other > 1)
      top.fail(key, "a microstructure fraction is free within [0, 1 - " +
                        std::string(slit ? "gapped" : "slit") + "] = [0, " +
                        format_double(1 - other) + "] (bonded takes the remainder), not a ratio");
  }
  return p;
}

void read_targets(CalibrationFile& c, JsonObject& top) {
  JsonObject t = top.object("targets");
  std::vector<std::string> known;
  for (const TargetNeed& n : target_needs())
    known.push_back(n.property);
  for (const auto& [name, v] : top.raw("targets").items()) {
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      std::string list;
      for (const std::string& k : known)
        list += (list.empty() ? "" : ", ") + k;
      t.fail(name, "unknown target; allowed: " + list);
    }
    JsonObject o = t.object(name);
    Target g;
    g.property = name;
    g.value = o.number("value", Range::any());
    g.absolute = o.boolean("absolute", false);
    g.tolerance = o.number("tolerance", g.absolute ? Range::positive() : Range::closed(1e-4, 1));
    if (!g.absolute && g.value == 0)
      o.fail("value", "a relative tolerance needs a non-zero target (or \"absolute\": true)");
    o.finish();
    c.targets.push_back(g);
  }
  if (c.targets.empty())
    top.fail("targets", "no target given");
}

// Every target must be measured by the listed tests.
void check_coverage(const CalibrationFile& c, JsonObject& top) {
  std::map<std::string, int> have;
  for (const auto& t : c.tests)
    if (t.is_object() && t.contains("test") && t["test"].is_string())
      ++have[t["test"].get<std::string>()];
  for (const Target& t : c.targets)
    for (const TargetNeed& n : target_needs()) {
      if (t.property != n.property)
        continue;
      if (have[n.test] < n.count || (n.other && have[n.other] < 1))
        top.fail("targets", "target \"" + t.property + "\" needs " + std::to_string(n.count) +
                                " \"" + n.test + "\" test(s)" +
                                (n.other ? std::string(" and a \"") + n.other + "\" test" : "") +
                                " in \"tests\"");
    }
}

// A calibration file read with its "extends" chain: the named file's keys, each replaced whole by
// the extending file's own (so a variant names only what differs: its start card, its budget).
// `material_from` is the file whose "material" the result uses (its path is relative to that file).
nlohmann::json read_extended(const std::string& path, std::string& material_from, int depth = 0) {
  nlohmann::json j = read_json_file(path);
  material_from = path;
  if (!j.is_object() || !j.contains("extends"))
    return j;
  const nlohmann::json& e = j["extends"];
  if (!e.is_string() || e.get<std::string>().empty())
    throw InputError(path + ": key 'extends': a calibration file's path (a string)");
  const std::string base = resolve(path, e.get<std::string>());
  if (!fs::exists(base))
    throw InputError(path + ": key 'extends': \"" + base + "\" does not exist");
  if (depth >= 8)
    throw InputError(path + ": key 'extends': more than 8 files deep (a file extending itself?)");
  std::string base_material;
  nlohmann::json merged =
      named_by(path, "extends", [&] { return read_extended(base, base_material, depth + 1); });
  if (!merged.is_object())
    throw InputError(path + ": key 'extends': \"" + base + "\" is not a JSON object");
  material_from = j.contains("material") ? path : base_material;
  for (const auto& [key, v] : j.items())
    if (key != "extends")
      merged[key] = v;
  return merged;
}

// Each parameter at each end of its bounds (the others at their start) gives a card the card
// reader takes: a bound beyond what the model's own reader allows (a stiffness ratio below its
// 1e-3, a fraction past 1) is refused here, naming the parameter, not at a genesis hours later.
// Ratios keep their denominator's start.
void check_bounds_readable(const CalibrationFile& c, const std::string& path) {
  std::vector<double> start;
  for (const CardParam& p : c.params)
    start.push_back(p.param.value);
  for (std::size_t i = 0; i < c.params.size(); ++i)
    for (const double end : {c.params[i].param.lo, c.params[i].param.hi}) {
      std::vector<double> v = start;
      v[i] = end;
      const std::string name = c.material_file + " (parameter at " + format_double(end) + ")";
      const InputText card(name, apply_params(c.material, c.params, v).dump());
      named_by(path, "parameters." + c.params[i].key + ".bounds",
               [&] { return load_material_card(name); });
    }
}

} // namespace

CalibrationFile load_calibration(const std::string& path) {
  CalibrationFile c;
  c.file = path;
  std::string material_from;
  const nlohmann::json j = read_extended(path, material_from);
  JsonObject top(j, path, "");
  c.name = read_header(top, fs::path(path).stem().string()).name;
  top.string("source", "");
  const std::string m = top.string("material");
  c.material_file = resolve(material_from, m);
  if (!fs::exists(c.material_file))
    top.fail("material", "\"" + c.material_file + "\" does not exist");
  // The base card must be valid on its own.
  named_by(path, "material", [&] { return load_material_card(c.material_file); });
  c.material = read_json_file(c.material_file);
  read_targets(c, top);
  JsonObject params = top.object("parameters");
  for (const auto& [key, v] : top.raw("parameters").items())
    c.params.push_back(read_param(c, params, key));
  if (c.params.empty())
    top.fail("parameters", "no free parameter given");
  for (const CardParam& p : c.params)
    if (!p.over.empty() && std::none_of(c.params.begin(), c.params.end(), [&](const CardParam& q) {
          return q.over.empty() && q.path == p.over;
        }))
      params.fail(p.key, "a ratio's denominator \"" + p.over + "\" must be a free parameter too");
  check_bounds_readable(c, path);
  for (const auto& [t, tpath] : top.array("tests"))
    c.tests.push_back(*t);
  check_coverage(c, top);
  for (const auto& [s, spath] : top.array("seeds", false)) {
    if (!s->is_number_integer() || s->get<std::int64_t>() < 0)
      throw InputError(path + ": key '" + spath + "': a seed must be a non-negative integer");
    c.seeds.push_back(s->get<std::uint64_t>());
  }
  if (c.seeds.empty())
    c.seeds = {1, 2, 3};
  // Per-seed results merged and kept (lab/calibration/seed_rows.hpp); default OUTDIR/seeds.csv.
  if (top.has("seeds_file"))
    c.seeds_file = resolve(path, top.string("seeds_file"));
  JsonObject b = top.optional_object("budget");
  c.budget.elastic = static_cast<int>(b.integer("elastic", 0, 100, c.budget.elastic));
  c.budget.strength = static_cast<int>(b.integer("strength", 0, 100, c.budget.strength));
  c.budget.ratios = static_cast<int>(b.integer("ratios", 0, 1000, c.budget.ratios));
  c.budget.polish = static_cast<int>(b.integer("polish", 0, 100, c.budget.polish));
  c.budget.sensitivity = b.boolean("sensitivity", c.budget.sensitivity);
  const int listed = static_cast<int>(c.seeds.size());
  c.budget.max_seeds = static_cast<int>(b.integer("max_seeds", 0, 100, 0));
  if (c.budget.max_seeds > 0 && c.budget.max_seeds < listed)
    b.fail("max_seeds", "must be 0 (automatic) or at least the " + std::to_string(listed) +
                            " seeds listed in \"seeds\"");
  if (c.budget.max_seeds == 0) // automatic: the listed seeds, at least 6
    c.budget.max_seeds = std::max(listed, 6);
  c.budget.validation_min =
      static_cast<int>(b.integer("validation_min", 2, 1000, c.budget.validation_min));
  c.budget.validation_max =
      static_cast<int>(b.integer("validation_max", 0, 1000, c.budget.validation_max));
  if (c.budget.validation_max > 0 && c.budget.validation_max < c.budget.validation_min)
    b.fail("validation_max", "must be 0 (no validation) or at least budget.validation_min (" +
                                 std::to_string(c.budget.validation_min) + ")");
  c.budget.validation_rounds =
      static_cast<int>(b.integer("validation_rounds", 1, 20, c.budget.validation_rounds));
  c.budget.validation_first =
      static_cast<std::uint64_t>(b.integer("validation_first", 0, std::int64_t{1} << 50,
                                           static_cast<std::int64_t>(c.budget.validation_first)));
  b.finish();
  top.finish();
  return c;
}

namespace {

// Set the card value at "section.key" to `v`: a {"mean", "sd"} distribution keeps its
// coefficient of variation.
void set_value(nlohmann::json& card, const std::string& path, double v) {
  nlohmann::json* x = &value_at(card, path);
  if (x->is_object() && x->contains("mean")) {
    const double mean = (*x)["mean"].get<double>();
    if (x->contains("sd") && mean != 0)
      (*x)["sd"] = (*x)["sd"].get<double>() * v / mean;
    (*x)["mean"] = v;
  } else {
    *x = v;
  }
}

// A free gapped or slit fraction takes its share from the bonded one (the three sum to 1).
void rebalance_fraction(nlohmann::json& card, const std::string& path) {
  if (const std::string types = fraction_parent(path); !types.empty()) {
    nlohmann::json& t = value_at(card, types);
    t["bonded"] = 1 - t.value("gapped", 0.0) - t.value("slit", 0.0);
  }
}

} // namespace

nlohmann::json override_card(const nlohmann::json& card,
                             const std::vector<std::pair<std::string, nlohmann::json>>& overrides,
                             const std::string& where) {
  nlohmann::json out = card;
  for (const auto& [path, v] : overrides) {
    const std::size_t dot = path.rfind('.');
    const std::string parent = dot == std::string::npos ? "" : path.substr(0, dot);
    const nlohmann::json* p = parent.empty() ? &out : card_value(out, parent);
    if (path.empty() || path.back() == '.' || !p || !p->is_object())
      throw InputError(where + ": override '" + path + "': the card has no section \"" + parent +
                       "\" (write \"section.key\", e.g. \"flatjoint.fj_ten\")");
    if (v.is_number() && !v.is_boolean())
      set_value(out, path, v.get<double>());
    else
      value_at(out, path) = v;
    rebalance_fraction(out, path);
  }
  return out;
}

nlohmann::json apply_params(const nlohmann::json& card, const std::vector<CardParam>& params,
                            const std::vector<double>& values) {
  nlohmann::json out = card;
  auto set = [&](const std::string& path, double v) { set_value(out, path, v); };
  for (int pass = 0; pass < 2; ++pass) // plain values first, then ratios over them
    for (std::size_t i = 0; i < params.size(); ++i) {
      const CardParam& p = params[i];
      if (p.over.empty() != (pass == 0))
        continue;
      set(p.path, pass == 0 ? values[i] : values[i] * number_of(*card_value(out, p.over)));
    }
  for (const CardParam& p : params)
    rebalance_fraction(out, p.path);
  return out;
}

} // namespace rocklab::calibration
