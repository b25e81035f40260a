#include "lab/protocol.hpp"

#include "io/json_input.hpp"
#include "io/results.hpp"
#include "lab/protocol_table.hpp"
#include "lab/protocols/frame_protocol.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace rocklab {

std::string resolve(const std::string& file, const std::string& p) {
  const std::filesystem::path path(p);
  if (path.is_absolute())
    return p;
  return (std::filesystem::path(file).parent_path() / path).lexically_normal().string();
}

Protocol protocol_from_json(const nlohmann::json& j, const std::string& file,
                            const std::string& key_path) {
  Protocol p;
  p.file = file;
  p.raw = j;
  JsonObject top(j, file, key_path);
  if (top.has("units") && top.string("units") != "SI")
    top.fail("units", "only \"SI\" is supported");
  p.name = top.string("name", "");
  top.string("description", "");
  p.test = top.choice("test", frame_test_names());
  const std::unique_ptr<FrameTest> test = make_frame_test(p.test);
  {
    if (!top.has("specimen"))
      top.fail("specimen", "missing: give {\"file\": SPECIMEN} or {\"material\": CARD}");
    JsonObject s = top.object("specimen");
    if (s.has("file") == s.has("material"))
      top.fail("specimen", "give exactly one of 'file' (a specimen file) or 'material' (a "
                           "material card run through genesis first)");
    if (s.has("file")) {
      p.specimen_file = resolve(file, s.string("file"));
      if (!std::filesystem::exists(p.specimen_file))
        s.fail("file", "\"" + p.specimen_file + "\" does not exist");
      if (!not_an_input_file(p.specimen_file).empty())
        s.fail("file", "\"" + p.specimen_file + "\" is not a specimen file");
    } else {
      p.material_file = resolve(file, s.string("material"));
      if (!std::filesystem::exists(p.material_file))
        s.fail("material", "\"" + p.material_file + "\" does not exist");
      if (!not_an_input_file(p.material_file).empty())
        s.fail("material", "\"" + p.material_file + "\" is not a material card file");
      if (s.has("shape"))
        p.shape = s.raw("shape");
      if (s.has("cut"))
        p.cut = s.raw("cut");
    }
    s.finish();
  }
  if (top.has("seed"))
    p.seed = static_cast<std::uint64_t>(
        top.integer("seed", 0, std::numeric_limits<std::int64_t>::max()));
  {
    JsonObject l = top.optional_object("loading");
    if (l.has("strain_rate") && l.has("platen_velocity"))
      l.fail("strain_rate", "give either 'strain_rate' (1/s) or 'platen_velocity' (m/s), not both");
    p.strain_rate = l.number("strain_rate", {0, 100, true, false}, kDefaultStrainRate, "1/s");
    if (l.has("platen_velocity"))
      p.platen_velocity = l.number("platen_velocity", {0, 100, true, false}, std::nullopt, "m/s");
    p.ramp_steps = l.integer("ramp_steps", 0, 10'000'000, 2000);
    p.seating_stress = l.number("seating_stress", Range::positive(), 1e5, "Pa");
    p.confinement = l.number("confinement", Range::non_negative(), 0.0, "Pa");
    p.confinement_tolerance = l.number("confinement_tolerance", {0, 0.5, true, false}, 0.01);
    p.grip_fraction = l.number("grip_fraction", {0, 0.4, true, false}, 0.1);
    p.reverse_at_strain = l.number("reverse_at_strain", {0, 0.1, false, false}, 0.0);
    if (l.choice("jaws", {"flat", "curved"}, "flat") == "curved")
      p.jaw_radius_ratio = l.number("jaw_radius_ratio", Range::closed(1.1, 10), 1.5);
    else if (l.has("jaw_radius_ratio"))
      l.fail("jaw_radius_ratio", "applies to \"jaws\": \"curved\" only");
    p.density_scaling = l.number("density_scaling", Range::half_open(0, 1), 0.0);
    if (l.has("timestep_safety"))
      p.timestep_safety = l.number("timestep_safety", {0, 1.6, true, false}, std::nullopt);
    if (l.has("platen_friction"))
      p.platen_friction = l.number("platen_friction", Range::closed(0, 10), std::nullopt);
    test->check_loading(l, p);
    l.finish();
  }
  {
    JsonObject s = top.optional_object("stop");
    p.post_peak_fraction = s.number("post_peak_fraction", {0, 1, true, true}, 0.9);
    p.min_steps = s.integer("min_steps", 0, std::numeric_limits<std::int64_t>::max(), 1000);
    p.strain_limit = s.number("strain_limit", Range::non_negative(), 0.0);
    p.split_fraction = s.number("split_fraction", Range::closed(0, 1), 0.6);
    p.failed_fraction = s.number("failed_fraction", {0, 1, true, false}, 0.3);
    test->check_stop(s);
    if (p.failed_fraction >= p.post_peak_fraction)
      s.fail("failed_fraction",
             "must be below stop.post_peak_fraction (" + format_double(p.post_peak_fraction) + ")");
    p.max_steps = s.integer("max_steps", 1, std::numeric_limits<std::int64_t>::max(), 5'000'000);
    s.finish();
  }
  {
    JsonObject o = top.optional_object("output");
    p.history_every = o.integer("history_every", 1, 10'000'000, 100);
    p.vtk_every_strain = o.number("vtk_every_strain", Range::non_negative(), 5e-4);
    p.vtk = o.boolean("vtk", true);
    p.plots = o.boolean("plots", true);
    p.orientation = o.boolean("orientation", false);
    p.cells = o.boolean("cells", true);
    p.event_window = o.number("event_window_s", Range::non_negative(), 0.0);
    o.finish();
  }
  top.finish();
  return p;
}

Protocol load_protocol(const std::string& path) {
  const nlohmann::json j = read_json_file(path);
  Protocol p = protocol_from_json(j, path, "");
  p.text_hash = text_hash(read_input_text(path));
  return p;
}

} // namespace rocklab
