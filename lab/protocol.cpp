#include "lab/protocol.hpp"

#include "io/json_input.hpp"
#include "io/results.hpp"
#include "lab/frame/frame_test.hpp"
#include "lab/protocol_table.hpp"

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

namespace {

void read_common_loading(JsonObject& l, Protocol& p) {
  if (l.has("strain_rate") && l.has("platen_velocity"))
    l.fail("strain_rate", "give either 'strain_rate' (1/s) or 'platen_velocity' (m/s), not both");
  p.strain_rate = l.number("strain_rate", {0, 100, true, false}, kDefaultStrainRate, "1/s");
  if (l.has("platen_velocity"))
    p.platen_velocity = l.number("platen_velocity", {0, 100, true, false}, std::nullopt, "m/s");
  p.ramp_steps = l.integer("ramp_steps", 0, 10'000'000, 2000);
  p.seating_stress = l.number("seating_stress", Range::positive(), 1e5, "Pa");
  p.approach_stress = l.number("approach_stress", Range::closed(0, 1e10), 0.0, "Pa");
  p.approach_rate = l.number("approach_rate", Range::closed(1, 20), 3.0);
  p.density_scaling = l.number("density_scaling", Range::half_open(0, 1), 0.0);
  if (l.has("timestep_safety"))
    p.timestep_safety = l.number("timestep_safety", {0, 1.6, true, false}, std::nullopt);
  if (l.has("platen_friction")) // the one reader of the key; the actuators take it from here
    p.platen_friction = l.number("platen_friction", Range::closed(0, 10), std::nullopt);
}

void read_common_stop(JsonObject& s, Protocol& p) {
  p.post_peak_fraction = s.number("post_peak_fraction", {0, 1, true, true}, 0.9);
  p.min_steps = s.integer("min_steps", 0, std::numeric_limits<std::int64_t>::max(), 1000);
  // 0: none. Below 1e-12 a strain is lost in the rounding of the grains' positions (1e-320 ran
  // and reported nothing); above 1 the specimen is gone. (A limit before the elastic window, e.g.
  // 1e-6, is computable: the test reports its E as not measured.)
  p.strain_limit = s.number("strain_limit", Range::closed(0, 1), 0.0);
  if (p.strain_limit > 0 && p.strain_limit < 1e-12)
    s.fail("strain_limit", "value " + s.raw("strain_limit").dump() +
                               " is out of range: 0 (no limit) or [1e-12, 1] (a smaller strain is "
                               "lost in the rounding of the grains' positions)");
  p.max_steps = s.integer("max_steps", 1, std::numeric_limits<std::int64_t>::max(), 5'000'000);
}

// A key this test does not read but another test does: named with the tests it applies to
// (found by letting each other test read the same section), not as an unknown key.
void refuse_other_tests_keys(JsonObject& section, const FrameTest& test) {
  for (const std::string& key : section.unread()) {
    nlohmann::json one = nlohmann::json::object();
    one[key] = section.json().at(key);
    std::vector<std::string> tests;
    for (const std::string& name : frame_test_names()) {
      if (name == test.name())
        continue;
      const std::unique_ptr<FrameTest> other = make_frame_test(name);
      const nlohmann::json empty = nlohmann::json::object();
      JsonObject probe(one, section.file(), section.path()), none(empty, "", "");
      Protocol scratch;
      for (const bool as_stop : {false, true}) {
        try { // as a loading key, then as a stop key (a test that fails on the missing rest)
          other->read_options(as_stop ? none : probe, as_stop ? probe : none, scratch);
        } catch (const InputError&) {
        }
      }
      if (probe.was_read(key))
        tests.push_back(name);
    }
    if (tests.empty())
      continue; // an unknown key: finish() lists the allowed ones
    std::string list;
    for (std::size_t i = 0; i < tests.size(); ++i)
      list += (i ? " and " : "") + tests[i];
    section.fail(key, "applies to the " + list + " test" + (tests.size() > 1 ? "s" : "") + " only");
  }
}

} // namespace

Protocol protocol_from_json(const nlohmann::json& j, const std::string& file,
                            const std::string& key_path, std::shared_ptr<FrameTest> test_object) {
  Protocol p;
  p.file = file;
  p.raw = j;
  JsonObject top(j, file, key_path);
  p.name = read_header(top, "").name;
  p.test = top.choice("test", frame_test_names());
  p.frame_test = test_object ? std::move(test_object) : make_frame_test(p.test);
  FrameTest& test = *p.frame_test;
  if (test.name() != p.test)
    throw std::logic_error("a " + std::string(test.name()) + " test object was given a " + p.test +
                           " protocol");
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
    JsonObject s = top.optional_object("stop");
    read_common_loading(l, p);
    read_common_stop(s, p);
    test.read_options(l, s, p); // the test's own keys
    refuse_other_tests_keys(l, test);
    refuse_other_tests_keys(s, test);
    l.finish();
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
    p.moment_tensors = o.boolean("moment_tensors", true);
    o.finish();
  }
  top.finish();
  return p;
}

Protocol load_protocol(const std::string& path, std::shared_ptr<FrameTest> test) {
  const nlohmann::json j = read_json_file(path);
  Protocol p = protocol_from_json(j, path, "", std::move(test));
  p.text_hash = text_hash(read_input_text(path));
  return p;
}

} // namespace rocklab
