// Genesis stage cache: the compacted and installed packing (the model after compaction, the run's
// state and the report so far) kept in a folder for reuse. Everything before finalization reads
// only the grains, the vessel, the packing and installation settings and the linear springs, not
// the bonds, so a calibration that moves strengths, type fractions or (below the packing margin)
// the installation gap packs each seed once. A hit restores the exact model (the specimen file's
// archive), so the specimen is byte-identical to the one made without the cache. Units SI.
#include "materials/genesis/stages.hpp"

#include "io/specimen.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace rocklab::genesis {

namespace {

constexpr const char* kFormat = "rocklab-packing-cache 1";

// The running program's bytes: any rebuild changes the key, so a packing made by other code is
// never reused.
const std::string& program_hash() {
  static const std::string h = [] {
    std::ifstream in("/proc/self/exe", std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return text_hash(s.str());
  }();
  return h;
}

nlohmann::json vec_json(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}
Vec3 vec_of(const nlohmann::json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

// The card's keys that packing, compaction and installation read: all of them except the
// bonds, joints, names, the installation gap (read as the packing margin it sets) and what
// finalization and release read.
nlohmann::json packing_inputs(const Run& g) {
  const MaterialCard& c = g.card;
  nlohmann::json j = c.raw;
  for (const char* k : {"name", "description", "source", "units", "flatjoint", "parallelbond",
                        "contactbond", "joints"})
    j.erase(k);
  if (j.contains("installation") && j["installation"].is_object())
    for (const char* k : {"gap", "gap_ratio", "draws", "residual_tolerance"})
      j["installation"].erase(k);
  char margin[40];
  std::snprintf(margin, sizeof margin, "%.17g", packing_margin(c, g.r_avg));
  return {{"format", kFormat},
          {"program", program_hash()},
          {"card", j},
          {"seed", c.seed},
          {"vessel", shape_json(c.vessel, c.dim)},
          {"cut", c.cut ? shape_json(*c.cut, c.dim) : nlohmann::json()},
          {"packing_margin", margin}};
}

nlohmann::json run_state(const Run& g) {
  std::ostringstream rng;
  rng << g.rng;
  nlohmann::json servos = nlohmann::json::array();
  for (const Servo& s : g.vessel.servos)
    servos.push_back({{"wall", s.wall}, {"n_in", vec_json(s.n_in)}, {"radial", s.radial}});
  const GenesisReport& r = g.rep;
  nlohmann::json walls = nlohmann::json::array();
  for (const auto& [name, s] : r.wall_stress)
    walls.push_back({name, s});
  return {{"r_avg", g.r_avg},
          {"speed_cap", g.speed_cap},
          {"largest_half", g.largest_half},
          {"installed_volume", g.installed_volume},
          {"rng", rng.str()},
          {"vessel", {{"dim", g.vessel.dim}, {"shape", static_cast<int>(g.vessel.shape)}}},
          {"servos", servos},
          {"report",
           {{"escaped", r.escaped},
            {"porosity_target", r.porosity_target},
            {"porosity_packed", r.porosity_packed},
            {"porosity_installed", r.porosity_installed},
            {"porosity", r.porosity},
            {"packing_friction", r.packing_friction},
            {"pressure", r.pressure},
            {"wall_stress", walls},
            {"shape", shape_json(r.shape, g.card.dim)},
            {"steps_packing", r.steps_packing},
            {"steps_installation", r.steps_installation}}}};
}

void restore_state(Run& g, const nlohmann::json& j, const std::string& file) {
  g.r_avg = j.at("r_avg").get<double>();
  g.speed_cap = j.at("speed_cap").get<double>();
  g.largest_half = j.at("largest_half").get<double>();
  g.installed_volume = j.at("installed_volume").get<double>();
  std::istringstream rng(j.at("rng").get<std::string>());
  rng >> g.rng;
  if (!rng)
    throw std::runtime_error(file + ": corrupt packing cache (random generator state)");
  g.vessel.dim = j.at("vessel").at("dim").get<int>();
  g.vessel.shape = static_cast<SpecimenShape>(j.at("vessel").at("shape").get<int>());
  g.vessel.servos.clear();
  for (const auto& s : j.at("servos"))
    g.vessel.servos.push_back(
        {s.at("wall").get<std::size_t>(), vec_of(s.at("n_in")), s.at("radial").get<bool>()});
  const auto& r = j.at("report");
  GenesisReport& rep = g.rep;
  rep.escaped = r.at("escaped").get<std::int64_t>();
  rep.porosity_target = r.at("porosity_target").get<double>();
  rep.porosity_packed = r.at("porosity_packed").get<double>();
  rep.porosity_installed = r.at("porosity_installed").get<double>();
  rep.porosity = r.at("porosity").get<double>();
  rep.packing_friction = r.at("packing_friction").get<double>();
  rep.pressure = r.at("pressure").get<double>();
  rep.wall_stress.clear();
  for (const auto& w : r.at("wall_stress"))
    rep.wall_stress.emplace_back(w.at(0).get<std::string>(), w.at(1).get<double>());
  rep.shape = shape_from_json(r.at("shape"), g.card.dim, file, "report.shape");
  rep.steps_packing = r.at("steps_packing").get<std::int64_t>();
  rep.steps_installation = r.at("steps_installation").get<std::int64_t>();
}

} // namespace

PackingKey packing_key(const Run& g) {
  const char* dir = std::getenv("ROCKLAB_PACKING_CACHE");
  if (!dir || !*dir || !g.card.packing_import.empty())
    return {};
  PackingKey k;
  k.inputs = packing_inputs(g);
  k.file = (std::filesystem::path(dir) / (text_hash(k.inputs.dump()) + ".rlpack")).string();
  return k;
}

bool load_packing(Run& g, const PackingKey& key) {
  if (key.file.empty() || !std::filesystem::exists(key.file))
    return false;
  nlohmann::json meta;
  std::unique_ptr<Model> m = load_model(key.file, &meta);
  // The name is a 64-bit hash: the file must also hold these very inputs.
  if (meta.value("inputs", nlohmann::json()) != key.inputs)
    return false;
  try {
    restore_state(g, meta.at("run"), key.file);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(key.file + ": corrupt packing cache (" + e.what() + ")");
  }
  g.m = std::move(*m);
  g.say("packing from the cache " + key.file);
  return true;
}

void store_packing(const Run& g, const PackingKey& key) {
  if (key.file.empty())
    return;
  std::filesystem::create_directories(std::filesystem::path(key.file).parent_path());
  // A name of this process's own, then one rename: concurrent campaigns may make the same packing.
  const std::string tmp = key.file + "." + std::to_string(::getpid());
  save_model(g.m, tmp, {{"inputs", key.inputs}, {"run", run_state(g)}});
  std::filesystem::rename(tmp, key.file);
}

} // namespace rocklab::genesis
