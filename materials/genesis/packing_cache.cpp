// Genesis stage cache: the compacted and installed packing (the model after compaction, the run's
// state and the report so far) kept in a folder for reuse. Everything before finalization reads
// only the grains, the vessel, the packing and installation settings and the linear springs, not
// the bonds, so a calibration that moves strengths, type fractions or (below the packing margin)
// the installation gap packs each seed once. A hit restores the exact model (the specimen file's
// archive), so the specimen is byte-identical to the one made without the cache. Units SI.
#include "materials/genesis/stages.hpp"

#include "io/json_fields.hpp"
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

// What the stages after compaction read of the run (besides the model), and the report so far,
// as named fields (io/json_fields.hpp, the checkpoints' archive).
struct PackedState {
  Run& g;
  template <class A> void fields(A& a) {
    GenesisReport& r = g.rep;
    std::string rng;
    if constexpr (!A::reading) {
      std::ostringstream s;
      s << g.rng;
      rng = s.str();
    }
    a("r_avg", g.r_avg), a("speed_cap", g.speed_cap), a("largest_half", g.largest_half);
    a("installed_volume", g.installed_volume), a("rng", rng);
    a("vessel_dim", g.vessel.dim), a("vessel_shape", g.vessel.shape);
    a.objects("servos", g.vessel.servos);
    a("escaped", r.escaped), a("porosity_target", r.porosity_target);
    a("porosity_packed", r.porosity_packed), a("porosity_installed", r.porosity_installed);
    a("porosity", r.porosity), a("packing_friction", r.packing_friction);
    a("pressure", r.pressure), a("wall_stress", r.wall_stress);
    a("shape", r.shape.shape), a("shape_size", r.shape.size);
    a("steps_packing", r.steps_packing), a("steps_installation", r.steps_installation);
    if constexpr (A::reading) {
      std::istringstream s(rng);
      s >> g.rng;
      if (!s)
        throw InputError(a.file + ": corrupt packing cache (random generator state)");
    }
  }
};

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
  JsonFieldReader r{meta.value("run", nlohmann::json()), key.file};
  PackedState{g}.fields(r);
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
  nlohmann::json state = nlohmann::json::object();
  JsonFieldWriter w{state};
  PackedState{const_cast<Run&>(g)}.fields(w); // the writer only reads
  save_model(g.m, tmp, {{"inputs", key.inputs}, {"run", state}});
  std::filesystem::rename(tmp, key.file);
}

} // namespace rocklab::genesis
