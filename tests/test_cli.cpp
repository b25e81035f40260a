// The command line: determinism, bad input, examples.
#include "helpers.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <vector>

namespace fs = std::filesystem;
using rocklab::test::binary;
using rocklab::test::read_file;
using rocklab::test::run_command;
using rocklab::test::source_dir;

namespace {
fs::path scratch(const std::string& name) {
  const fs::path p = rocklab::test::scratch_root() / ("rocklab-test-" + name);
  fs::remove_all(p);
  return p;
}
fs::path write_scene(const std::string& name, const std::string& text) {
  const fs::path p = rocklab::test::scratch_root() / ("rocklab-scene-" + name + ".json");
  std::ofstream(p) << text;
  return p;
}
// A scene that must stop as a physical blow-up: exit 3, each message on the output, no OUTDIR.
void expect_blowup(const std::string& name, const std::string& text,
                   const std::vector<std::string>& messages) {
  const fs::path scene = write_scene(name, text);
  const fs::path out = scratch(name);
  std::string msg;
  EXPECT_EQ(run_command(binary() + " run " + scene.string() + " -o " + out.string(), &msg), 3);
  for (const std::string& m : messages)
    EXPECT_NE(msg.find(m), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(out));
}
const char* kGoodScene = R"({
  "dimension": 3,
  "balls": [{"id": 1, "position": [0, 0, 0.0105], "radius": 0.01, "density": 2650}],
  "walls": [{"name": "floor", "plane": {"point": [0, 0, 0], "normal": [0, 0, 1], "extent": 1}}],
  "gravity": [0, 0, -9.81],
  "contact_models": [{"between": "ball-facet", "model": "linear", "properties": {"kn": 1e4}}],
  "run": {"cycles": 100}
})";
} // namespace

TEST(Cli, DeterministicAcrossThreadsAndRepeats) {
  const std::string scene = source_dir() + "/examples/settling_2k.json";
  std::string out;
  const fs::path a = scratch("det-1"), b = scratch("det-2"), c = scratch("det-2b");
  ASSERT_EQ(run_command(binary() + " run " + scene + " -o " + a.string() + " --threads 1 -q", &out),
            0)
      << out;
  ASSERT_EQ(run_command(binary() + " run " + scene + " -o " + b.string() + " --threads 2 -q", &out),
            0)
      << out;
  ASSERT_EQ(run_command(binary() + " run " + scene + " -o " + c.string() + " --threads 2 -q", &out),
            0)
      << out;
  const std::string ra = read_file(a / "results.json");
  ASSERT_GT(ra.size(), 100000u);
  EXPECT_EQ(ra, read_file(b / "results.json"));
  EXPECT_EQ(ra, read_file(c / "results.json"));
  EXPECT_EQ(read_file(a / "history.csv"), read_file(b / "history.csv"));
  // The scene really is dynamic: many contacts were created and most balls carry load.
  EXPECT_NE(ra.find("\"contact_created\""), std::string::npos);
}

TEST(Cli, MalformedJson) {
  const fs::path scene = write_scene("malformed", "{\"dimension\": 3,, }");
  const fs::path out = scratch("malformed");
  std::string msg;
  EXPECT_EQ(run_command(binary() + " run " + scene.string() + " -o " + out.string(), &msg), 2);
  EXPECT_NE(msg.find(scene.string() + ":1:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("malformed JSON"), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, UnknownKey) {
  std::string text = kGoodScene;
  text.replace(text.find("\"radius\""), 8, "\"raduis\"");
  const fs::path scene = write_scene("unknown", text);
  const fs::path out = scratch("unknown");
  std::string msg;
  EXPECT_EQ(run_command(binary() + " run " + scene.string() + " -o " + out.string(), &msg), 2);
  // A misspelt required key is reported as missing first; an extra key as unknown.
  EXPECT_NE(msg.find("balls[0].radius"), std::string::npos) << msg;
  text = kGoodScene;
  text.replace(text.find("\"density\": 2650"), 15, "\"density\": 2650, \"colour\": 1");
  const fs::path scene2 = write_scene("unknown2", text);
  EXPECT_EQ(run_command(binary() + " run " + scene2.string() + " -o " + out.string(), &msg), 2);
  EXPECT_NE(msg.find("unknown key 'balls[0].colour'"), std::string::npos) << msg;
  EXPECT_NE(msg.find(scene2.string()), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, NegativeRadius) {
  std::string text = kGoodScene;
  text.replace(text.find("\"radius\": 0.01"), 14, "\"radius\": -0.01");
  const fs::path scene = write_scene("negative", text);
  const fs::path out = scratch("negative");
  std::string msg;
  EXPECT_EQ(run_command(binary() + " run " + scene.string() + " -o " + out.string(), &msg), 2);
  EXPECT_NE(msg.find("key 'balls[0].radius': value -0.01 is out of range (0, +inf) m"),
            std::string::npos)
      << msg;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, WrongType) {
  std::string text = kGoodScene;
  text.replace(text.find("\"cycles\": 100"), 13, "\"cycles\": \"many\"");
  const fs::path scene = write_scene("wrongtype", text);
  const fs::path out = scratch("wrongtype");
  std::string msg;
  EXPECT_EQ(run_command(binary() + " run " + scene.string() + " -o " + out.string(), &msg), 2);
  EXPECT_NE(msg.find("key 'run.cycles': expected an integer"), std::string::npos) << msg;
}

TEST(Cli, DuplicateKeysHugeNumbersDeepNestingNullsAndDirectoriesAreInputErrors) {
  // JSON keeps the last of two equal keys silently (a ball given "velocity" twice was taken at
  // rest), a null was taken as an absent key; 1e400 and a directory as the input file came out as
  // library text with exit 1; deep nesting once overflowed the stack.
  std::string twice = kGoodScene;
  twice.replace(twice.find("\"density\": 2650"), 15, "\"density\": 2650, \"density\": 3000");
  std::string huge = kGoodScene;
  huge.replace(huge.find("\"cycles\": 100"), 13, "\"cycles\": 1e400");
  const std::string deep = "{\"dimension\": " + std::string(300, '[') + std::string(300, ']') + "}";
  const fs::path dir = rocklab::test::scratch_root() / "rocklab-scene-dir.json";
  fs::create_directories(dir);
  const std::vector<std::pair<fs::path, std::string>> cases{
      {write_scene("twice", twice), "key 'balls[0].density' appears twice"},
      {write_scene("huge", huge), "number overflow parsing '1e400'"},
      {write_scene("deep", deep), "key 'dimension[0][0]"},
      {write_scene("null", R"({"dimension": 3, "balls": [{"id": 1, "position": [0, null, 0]}]})"),
       "key 'balls[0].position[1]': null is not a value here"},
      {dir, "is a directory, not an input file"},
      {"/dev/zero", "is a device or socket, not an input file"}};
  for (const auto& [scene, message] : cases) {
    const fs::path out = scratch("badjson");
    std::string msg;
    EXPECT_EQ(run_command(binary() + " run " + scene.string() + " -o " + out.string(), &msg), 2)
        << msg;
    EXPECT_NE(msg.find(scene.string() + ": "), std::string::npos) << msg;
    EXPECT_NE(msg.find(message), std::string::npos) << msg;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST(Cli, MissingFile) {
  const fs::path out = scratch("missing");
  std::string msg;
  EXPECT_EQ(run_command(binary() + " run /nonexistent/scene.json -o " + out.string(), &msg), 2);
  EXPECT_NE(msg.find("/nonexistent/scene.json: cannot open file"), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, ExistingOutputDirIsLeftUntouchedOnError) {
  const fs::path out = scratch("existing");
  fs::create_directories(out);
  std::ofstream(out / "keep.txt") << "old";
  std::string text = kGoodScene;
  text.replace(text.find("\"radius\": 0.01"), 14, "\"radius\": -0.01");
  const fs::path scene = write_scene("existing", text);
  EXPECT_EQ(run_command(binary() + " run " + scene.string() + " -o " + out.string()), 2);
  EXPECT_EQ(read_file(out / "keep.txt"), "old");
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(out))
    ++n;
  EXPECT_EQ(n, 1u);
}

TEST(Cli, BlowUpStopsWithAMessage) {
  // A ball fired into a very soft facet overlaps beyond its radius.
  const std::string text = R"({
    "dimension": 3,
    "balls": [{"position": [0, 0, 0.011], "radius": 0.01, "density": 2650, "velocity": [0, 0, -50]}],
    "walls": [{"name": "floor", "plane": {"point": [0, 0, 0], "normal": [0, 0, 1], "extent": 1}}],
    "contact_models": [{"between": "ball-facet", "model": "linear", "properties": {"kn": 1}}],
    "run": {"cycles": 100}})";
  expect_blowup("blowup", text, {"physical blow-up", "overlap beyond a radius"});
}

TEST(Cli, ASpinNoStepCanFollowStopsAsABlowUp) {
  // Two touching balls, one spinning at 1e308 rad/s: the run wrote null energies and exited 0.
  const std::string text = R"({
    "dimension": 3,
    "balls": [{"position": [0, 0, 0], "radius": 0.01, "density": 2650, "spin": [0, 0, 1e308]},
              {"position": [0.0199, 0, 0], "radius": 0.01, "density": 2650}],
    "contact_models": [{"between": "ball-ball", "model": "linear", "properties": {"kn": 1e6}}],
    "run": {"cycles": 100}})";
  expect_blowup("spin", text, {"physical blow-up", "more than 1 rad"});
}

TEST(Cli, TheFlatJointBondMethodKeepsToItsGapFilter) {
  // Issue 16: the flat joint's (and contact bond's) bond method bonded every contact whatever its
  // gap (88 extra bonds on a 9,896-grain packing). Two balls 1 um apart, unbonded at creation,
  // pulled apart after the method: bonded, the joint's elements carry the pull (strain energy).
  auto strain = [&](const std::string& name, const std::string& gap) {
    const std::string text = R"({"dimension": 2, "local_damping": 0.7, "timestep": 1e-7,
      "balls": [{"id": 1, "position": [0, 0], "radius": 0.00625, "density": 2650, "fix": "all"},
                {"id": 2, "position": [0.012501, 0], "radius": 0.00625, "density": 2650,
                 "fix": "all"}],
      "contact_models": [{"between": "ball-ball", "model": "flatjoint", "properties": {
        "fj_Nr": 2, "fj_rmul": 0.8, "fj_kn": 2e12, "fj_ks": 1e12, "fj_ten": 1e20, "fj_coh": 1e20,
        "bond": false}}],
      "history": {"every": 10, "columns": ["energy/strain"]},
      "run": [{"cycles": 1},
              {"cycles": 1, "methods": [{"model": "flatjoint", "method": "bond")" +
                             gap + R"(}]},
              {"cycles": 50, "set": [{"ball": 2, "velocity": [0.01, 0]}]}]})";
    const fs::path scene = write_scene(name, text);
    const fs::path out = scratch(name);
    std::string msg;
    EXPECT_EQ(
        run_command(binary() + " run " + scene.string() + " -o " + out.string() + " -q", &msg), 0)
        << msg;
    const std::string h = read_file(out / "history.csv");
    const std::string last = h.substr(h.rfind('\n', h.size() - 2) + 1);
    return std::stod(last.substr(last.rfind(',') + 1));
  };
  EXPECT_EQ(strain("fjgap-default", ""), 0.0); // gap 1 um > 0: not bonded
  EXPECT_GT(strain("fjgap-wide", R"(, "gap": [-1, 1e-5])"), 0.0);
}

TEST(Cli, TooLargeFixedStepStopsWithAMessage) {
  // With a fixed step of 1 ms a ball at 50 m/s would jump through the floor unseen.
  const std::string text = R"({
    "dimension": 3, "timestep": 1e-3,
    "balls": [{"position": [0, 0, 0.011], "radius": 0.01, "density": 2650, "velocity": [0, 0, -50]}],
    "walls": [{"name": "floor", "plane": {"point": [0, 0, 0], "normal": [0, 0, 1], "extent": 1}}],
    "contact_models": [{"between": "ball-facet", "model": "linear", "properties": {"kn": 1e4}}],
    "run": {"cycles": 100}})";
  expect_blowup("bigstep", text, {"more than its radius"});
}

TEST(Cli, HelpAndVersion) {
  std::string msg;
  EXPECT_EQ(run_command(binary() + " --version", &msg), 0);
  EXPECT_NE(msg.find("rocklab"), std::string::npos);
  EXPECT_EQ(run_command(binary() + " --help", &msg), 0);
  EXPECT_NE(msg.find("run"), std::string::npos);
  EXPECT_NE(msg.find("SI"), std::string::npos);
}

TEST(Cli, BadCommandLinesExitWithTwoAndSayWhy) {
  // No subcommand: the usage; an unknown option, a missing argument or a negative count: CLI11's
  // message. Every one is an input error (status 2), never CLI11's own 100+ codes.
  std::string msg;
  EXPECT_EQ(run_command(binary(), &msg), 2);
  EXPECT_NE(msg.find("genesis"), std::string::npos) << msg;
  EXPECT_EQ(run_command(binary() + " test", &msg), 2);
  EXPECT_NE(msg.find("protocol"), std::string::npos) << msg;
  EXPECT_EQ(run_command(binary() + " genesis x.json -o y --seed -5", &msg), 2);
  EXPECT_NE(msg.find("seed"), std::string::npos) << msg;
  EXPECT_EQ(run_command(binary() + " genesis x.json -o y --seed 99999999999999999999999", &msg), 2);
  EXPECT_NE(msg.find("seed"), std::string::npos) << msg;
  EXPECT_EQ(run_command(binary() + " info --bogus", &msg), 2);
  EXPECT_NE(msg.find("bogus"), std::string::npos) << msg;
}

TEST(Cli, AShapeOnTheCommandLineIsReadAsAnInputFileIs) {
  // A 60,000-deep array given to --shape crashed the recursive JSON parser (segmentation
  // fault); it now meets the input files' depth limit, and malformed JSON names the option.
  const fs::path deep = rocklab::test::scratch_root() / "deep_shape.json";
  {
    std::ofstream f(deep);
    f << std::string(60000, '[') << std::string(60000, ']');
  }
  const std::string card = source_dir() + "/materials/granite_fj_2d.json";
  const fs::path out = rocklab::test::scratch_root() / "deep_shape.rlspec";
  std::string msg;
  EXPECT_EQ(run_command(binary() + " genesis " + card + " -o " + out.string() +
                            " -q --shape \"$(cat " + deep.string() + ")\"",
                        &msg),
            2);
  EXPECT_NE(msg.find("--shape"), std::string::npos) << msg.substr(0, 300);
  EXPECT_NE(msg.find("deeper than 256"), std::string::npos) << msg.substr(0, 300);
  EXPECT_EQ(run_command(binary() + " genesis " + card + " -o " + out.string() +
                            " -q --cut '{\"shape\": '",
                        &msg),
            2);
  EXPECT_NE(msg.find("--cut"), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(out));
}

TEST(Cli, EveryExampleRuns) {
  std::size_t count = 0;
  for (const auto& entry : fs::recursive_directory_iterator(source_dir() + "/examples")) {
    if (entry.path().extension() != ".json")
      continue;
    const fs::path out = scratch("example-" + entry.path().stem().string());
    std::string msg;
    EXPECT_EQ(run_command(
                  binary() + " run " + entry.path().string() + " -o " + out.string() + " -q", &msg),
              0)
        << entry.path() << "\n"
        << msg;
    EXPECT_TRUE(fs::exists(out / "results.json")) << entry.path();
    EXPECT_TRUE(fs::exists(out / "history.csv")) << entry.path();
    ++count;
  }
  EXPECT_GE(count, 5u);
}

TEST(Cli, BondedModelsAreDeterministicAcrossThreads) {
  for (const char* name : {"interlocked_3d_exact", "smooth_joint_bonded_weak"}) {
    const std::string scene = source_dir() + "/examples/verification/" + name + ".json";
    const fs::path a = scratch(std::string("bdet-1-") + name),
                   b = scratch(std::string("bdet-2-") + name);
    std::string out;
    ASSERT_EQ(
        run_command(binary() + " run " + scene + " -o " + a.string() + " --threads 1 -q", &out), 0)
        << out;
    ASSERT_EQ(
        run_command(binary() + " run " + scene + " -o " + b.string() + " --threads 2 -q", &out), 0)
        << out;
    EXPECT_EQ(read_file(a / "results.json"), read_file(b / "results.json")) << name;
  }
}

// Issue 16 item 7: the unbalanced-force stop rule ignored moments, so a problem loaded by a moment
// alone stopped at step 0. Now a ball's unbalanced moment counts (over its radius) and nothing is
// checked before the first cycle: a bonded ball twisted by an applied moment turns until the
// bond's moment balances it.
TEST(Cli, TheUnbalancedForceStopCountsMoments) {
  const std::string text = R"({
    "dimension": 2, "local_damping": 0.7,
    "balls": [{"id": 1, "position": [0, 0], "radius": 0.01, "density": 2650, "fix": "all"},
              {"id": 2, "position": [0.02, 0], "radius": 0.01, "density": 2650,
               "fix": ["x", "y"], "moment": 0.5}],
    "contact_models": [{"between": "ball-ball", "model": "linearpbond",
                        "properties": {"kn": 1e7, "pb_kn": 1e12, "pb_ks": 1e12,
                                       "pb_ten": 1e20, "pb_coh": 1e20}}],
    "run": {"unbalanced_force_ratio": 1e-4, "max_cycles": 200000}
  })";
  const fs::path scene = write_scene("moment", text);
  const fs::path out = scratch("moment");
  std::string msg;
  ASSERT_EQ(run_command(binary() + " run " + scene.string() + " -o " + out.string() + " -q", &msg),
            0)
      << msg;
  const auto r = nlohmann::json::parse(read_file(out / "results.json"));
  EXPECT_GT(r["step"].get<long>(), 0);
  EXPECT_LT(r["step"].get<long>(), 200000); // stopped by the ratio, not the cycle limit
  // At rest the bond's moment and its shear force's moment about ball 2's centre (lever -R along
  // x) balance the applied 0.5 N m (to the ratio 1e-4 of the load).
  ASSERT_EQ(r["contacts"].size(), 1u);
  const auto& c = r["contacts"][0];
  const double about_centre = c["moment"].get<double>() - 0.01 * c["force"][1].get<double>();
  EXPECT_NEAR(about_centre, -0.5, 5e-3) << c.dump();
  EXPECT_GT(std::abs(c["moment"].get<double>()), 0.05) << c.dump(); // the bond carries its part
}

namespace {

// Two pairs of fixed balls 0.5 mm apart: one of 10 mm balls (gap 0.025 of R1 + R2, ids 1-2) and
// one of 1 mm balls (0.25, ids 3-4), with `contacts` as the scene's contact_models and `run` as
// its run. Returns each pair's `key` contact state in results.json by its first ball's id; empty
// when the run fails (its output in `msg`).
std::map<long, int> pair_states(const std::string& contacts, const std::string& run,
                                const char* key, std::string* msg) {
  const std::string text = R"({
    "dimension": 3, "margin": 0.001,
    "balls": [{"id": 1, "position": [0, 0, 0], "radius": 0.01, "density": 2650, "fix": "all"},
              {"id": 2, "position": [0.0205, 0, 0], "radius": 0.01, "density": 2650, "fix": "all"},
              {"id": 3, "position": [1, 0, 0], "radius": 0.001, "density": 2650, "fix": "all"},
              {"id": 4, "position": [1.0025, 0, 0], "radius": 0.001, "density": 2650, "fix": "all"}],
    "contact_models": )" + contacts +
                           R"(,
    "run": )" + run + "}";
  const fs::path scene = write_scene("gapratio", text);
  const fs::path out = scratch("gapratio");
  std::map<long, int> state;
  if (run_command(binary() + " run " + scene.string() + " -o " + out.string() + " -q", msg) != 0)
    return state;
  const auto r = nlohmann::json::parse(read_file(out / "results.json"));
  for (const auto& c : r["contacts"])
    state[c["end1"].get<long>()] = c["state"][key].get<int>();
  return state;
}

} // namespace

// Issue 16 item 7: bonds could only be made by an absolute gap. A stage's `methods` entry may give
// `gap_ratio` instead, a fraction of each contact's radii sum: of the two pairs above, bonded up
// to 0.05, only the first.
TEST(Cli, BondsCanBeMadeByAFractionOfTheRadiiSum) {
  const std::string contacts = R"([{"between": "ball-ball", "model": "linearpbond",
      "properties": {"kn": 1e6, "pb_kn": 1e12, "pb_ks": 1e12, "pb_ten": 1e8, "pb_coh": 1e8,
                     "bond": false}}])";
  auto bonded = [&](const std::string& gap, std::string* msg) {
    return pair_states(contacts,
                       R"([{"cycles": 1}, {"cycles": 1, "methods": [{"model": "linearpbond",
                           "method": "bond", )" +
                           gap + "}]}]",
                       "pb_state", msg);
  };
  std::string msg;
  const auto by_ratio = bonded("\"gap_ratio\": 0.05", &msg);
  ASSERT_EQ(by_ratio.size(), 2u) << msg;
  EXPECT_EQ(by_ratio.at(1), 3);                      // bonded: 0.025 of its radii sum
  EXPECT_EQ(by_ratio.at(3), 0);                      // not: 0.25
  const auto by_gap = bonded("\"gap\": 0.05", &msg); // 0.05 m: both
  ASSERT_EQ(by_gap.size(), 2u) << msg;
  EXPECT_EQ(by_gap.at(1), 3);
  EXPECT_EQ(by_gap.at(3), 3);
  // Both keys, or a ratio beyond the radii sum: input errors.
  EXPECT_TRUE(bonded("\"gap\": 0.1, \"gap_ratio\": 0.05", &msg).empty());
  EXPECT_NE(msg.find("give either 'gap'"), std::string::npos) << msg;
  EXPECT_TRUE(bonded("\"gap_ratio\": 2", &msg).empty());
  EXPECT_NE(msg.find("key 'run[1].methods[0].gap_ratio'"), std::string::npos) << msg;
}

// The same choice when a contact is created: a model's `bond` key takes {"gap_ratio": [lo, hi]}
// (parallel bond, contact bond, smooth joint and flat joint alike; a flat joint's `true` bonds
// every new contact, a range only the contacts whose creation gap lies in it).
TEST(Cli, NewContactsCanBeBondedByAFractionOfTheRadiiSum) {
  auto states = [](const std::string& model, const std::string& props, const std::string& bond,
                   const char* key, std::string* msg) {
    return pair_states(R"([{"between": "ball-ball", "model": ")" + model + R"(", "properties": )" +
                           props + R"(, "bond": )" + bond + "}}]",
                       R"({"cycles": 1})", key, msg);
  };
  std::string msg;
  const std::string pb =
      R"({"kn": 1e6, "pb_kn": 1e12, "pb_ks": 1e12, "pb_ten": 1e8, "pb_coh": 1e8)";
  const std::string fj = R"({"fj_kn": 1e12, "fj_ks": 1e12, "fj_ten": 1e8, "fj_coh": 1e8)";
  auto pbs = states("linearpbond", pb, R"({"gap_ratio": [-1, 0.05]})", "pb_state", &msg);
  ASSERT_EQ(pbs.size(), 2u) << msg;
  EXPECT_EQ(pbs.at(1), 3); // bonded
  EXPECT_EQ(pbs.at(3), 0); // not
  pbs = states("linearpbond", pb, R"({"gap": [-1, 0.001]})", "pb_state", &msg);
  ASSERT_EQ(pbs.size(), 2u) << msg;
  EXPECT_EQ(pbs.at(1), 3);
  EXPECT_EQ(pbs.at(3), 3);
  auto fjs = states("flatjoint", fj, R"({"gap_ratio": [-1, 0.05]})", "fj_mtype", &msg);
  ASSERT_EQ(fjs.size(), 2u) << msg;
  EXPECT_EQ(fjs.at(1), 1); // bonded
  EXPECT_EQ(fjs.at(3), 3); // slit
  fjs = states("flatjoint", fj, "true", "fj_mtype", &msg);
  ASSERT_EQ(fjs.size(), 2u) << msg;
  EXPECT_EQ(fjs.at(1), 1);
  EXPECT_EQ(fjs.at(3), 1);
  fjs = states("flatjoint", fj, "0.0001", "fj_mtype", &msg); // at most 0.1 mm: neither
  ASSERT_EQ(fjs.size(), 2u) << msg;
  EXPECT_EQ(fjs.at(1), 3);
  EXPECT_EQ(fjs.at(3), 3);
  // A ratio range beyond the radii sum, or reversed: input errors naming the key.
  for (const char* bad : {R"({"gap_ratio": [-1, 2]})", R"({"gap_ratio": [0.1, 0]})"}) {
    EXPECT_TRUE(states("linearpbond", pb, bad, "pb_state", &msg).empty()) << bad;
    EXPECT_NE(msg.find("'contact_models[0].properties.bond'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("within [-1, 1]"), std::string::npos) << msg;
  }
}

TEST(Cli, ALentCoreChangesNothingButTheWallTime) {
  // A suite or calibration lends idle cores to its running processes through a lease file
  // (src/core/thread_lease.hpp); the run follows it between one and two threads mid-run and must
  // give the same bits as a run on one thread throughout.
  const std::string scene = source_dir() + "/examples/settling_2k.json";
  const fs::path a = scratch("lease-fixed"), b = scratch("lease-lent");
  const fs::path lease = rocklab::test::scratch_root() / "rocklab-test-lease";
  std::ofstream(lease) << "2\n";
  std::string out;
  ASSERT_EQ(run_command(binary() + " run " + scene + " -o " + a.string() + " --threads 1 -q", &out),
            0)
      << out;
  const std::string flip = "(for i in 1 2 3 4 5 6 7 8 9 10 11 12; do echo $((i % 2 + 1)) > " +
                           lease.string() + ".new; mv " + lease.string() + ".new " +
                           lease.string() + "; sleep 0.25; done) & ";
  ASSERT_EQ(run_command("sh -c '" + flip + "ROCKLAB_THREAD_LEASE=" + lease.string() + " " +
                            binary() + " run " + scene + " -o " + b.string() +
                            " --threads 1 -q; s=$?; wait; exit $s'",
                        &out),
            0)
      << out;
  EXPECT_EQ(read_file(a / "results.json"), read_file(b / "results.json"));
  EXPECT_EQ(read_file(a / "history.csv"), read_file(b / "history.csv"));
  // ... and it does follow the lease: started on one thread, it ends on the two lent to it.
  std::ofstream(lease) << "2\n";
  ASSERT_EQ(run_command("ROCKLAB_THREAD_LEASE=" + lease.string() + " " + binary() + " run " +
                            scene + " -o " + scratch("lease-two").string() + " --threads 1",
                        &out),
            0)
      << out;
  EXPECT_NE(out.find("on 2 thread(s)"), std::string::npos) << out;
}
