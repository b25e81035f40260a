// Per-seed results of a calibration (lab/calibration/seed_rows.*): the CSV keeps every value
// exactly, refuses a malformed row naming the file and line, and a campaign resumed from such a
// file elsewhere reports the same validation row as the one that ran every seed.
#include "lab/calibration/seed_rows.hpp"

#include "helpers.hpp"
#include "io/input_error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>

using rocklab::calibration::SeedRows;
namespace fs = std::filesystem;

TEST(SeedRows, ValuesSurviveTheFileBitForBitAndAMalformedRowIsNamed) {
  const fs::path dir = rocklab::test::scratch_root() / "seed-rows";
  fs::remove_all(dir);
  const std::string path = (dir / "rows.csv").string();
  {
    SeedRows rows(path); // no file yet: empty
    EXPECT_EQ(rows.size(), 0u);
    rows.add("k2", 1002, {{"ucs_Pa", 2.0270001234567e8}, {"bts_Pa", nullptr}});
    rows.add("k1", 1001, {{"ucs_Pa", 1.0 / 3.0}, {"poisson_ratio", 0.2613}});
    rows.add("k1", 1001, {{"ucs_Pa", 0.1 + 0.2}}); // replaced, not duplicated
  }
  const SeedRows back(path);
  ASSERT_EQ(back.size(), 2u);
  ASSERT_NE(back.find("k1"), nullptr);
  EXPECT_EQ((*back.find("k1"))["ucs_Pa"].get<double>(), 0.1 + 0.2); // exact
  EXPECT_TRUE((*back.find("k1"))["bts_Pa"].is_null());              // column it never had
  EXPECT_EQ((*back.find("k2"))["ucs_Pa"].get<double>(), 2.0270001234567e8);
  EXPECT_TRUE((*back.find("k2"))["bts_Pa"].is_null());
  EXPECT_EQ(back.find("k3"), nullptr);
  EXPECT_EQ(rocklab::test::read_file(path).substr(0, 23), "key,seed,bts_Pa,ucs_Pa\n");
  for (const char* bad :
       {"key,seed,ucs_Pa\nk1,1001\n", "key,seed,ucs_Pa\nk1,x,3\n", "key,seed,ucs_Pa\nk1,1,3e5x\n",
        "seed,key\n", "key,seed,ucs_Pa\n,1,3\n"}) {
    std::ofstream(dir / "bad.csv") << bad;
    try {
      SeedRows rows((dir / "bad.csv").string());
      ADD_FAILURE() << "read: " << bad;
    } catch (const rocklab::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.csv: line "), std::string::npos) << e.what();
    }
  }
}

namespace {
// A validation of the tiny 2D specimen's E and UCS (the card as it is): seed 1, then 2 fresh seeds.
nlohmann::json tiny_validation(const std::string& seeds_file) {
  return {{"name", "tiny-validation"},
          {"units", "SI"},
          {"material", rocklab::test::source_dir() + "/tests/data/lab_2d_fj.json"},
          {"targets",
           {{"youngs_modulus_Pa", {{"value", 3e9}, {"tolerance", 0.05}}},
            {"ucs_Pa", {{"value", 20e6}, {"tolerance", 0.05}}}}},
          {"parameters", {{"flatjoint.fj_ten", {{"role", "strength"}, {"bounds", {1e5, 1e10}}}}}},
          {"tests",
           {{{"name", "ucs"}, {"test", "ucs"}, {"output", {{"vtk", false}, {"plots", false}}}}}},
          {"seeds", {1}},
          {"seeds_file", seeds_file},
          {"budget",
           {{"elastic", 0},
            {"strength", 0},
            {"ratios", 0},
            {"polish", 0},
            {"sensitivity", false},
            {"validation_min", 2},
            {"validation_max", 2}}}};
}
std::string validation_section(const std::string& report) {
  const auto a = report.find("## Validation on fresh seeds");
  const auto b = report.find("\n## ", a + 5);
  return a == std::string::npos ? "" : report.substr(a, b - a);
}
} // namespace

TEST(SeedRows, ACampaignResumedFromASeedsFileReportsTheSameRowAsOneThatRanThemAll) {
  const fs::path dir = rocklab::test::scratch_root() / "seed-rows-cli";
  fs::remove_all(dir);
  fs::create_directories(dir);
  auto run = [&](const std::string& name, const std::string& rows, std::string& said) {
    const std::string file = (dir / (name + ".json")).string();
    std::ofstream(file) << tiny_validation(rows).dump(2);
    const int status = rocklab::test::run_command(rocklab::test::binary() + " calibrate " + file +
                                                      " -o " + (dir / name).string() + " --jobs 1",
                                                  &said);
    return status;
  };
  std::string said;
  const int full = run("full", "rows.csv", said);
  ASSERT_TRUE(full == 0 || full == 1) << said;
  const std::string all = rocklab::test::read_file(dir / "rows.csv");
  ASSERT_EQ(std::count(all.begin(), all.end(), '\n'), 4) << all; // header + seeds 1, 1001, 1002
  const std::string reference =
      validation_section(rocklab::test::read_file(dir / "full/report.md"));
  ASSERT_FALSE(reference.empty());
  // Another output folder (another machine) with the whole file: nothing runs, the same row.
  fs::copy_file(dir / "rows.csv", dir / "copy.csv");
  ASSERT_EQ(run("merged", "copy.csv", said), full) << said;
  EXPECT_NE(said.find("(0 suites run"), std::string::npos) << said;
  EXPECT_EQ(validation_section(rocklab::test::read_file(dir / "merged/report.md")), reference);
  // A file holding two of the three seeds: only the third runs, and its row is added.
  std::string partial = all.substr(0, all.rfind('\n', all.size() - 2) + 1);
  std::ofstream(dir / "partial.csv") << partial;
  ASSERT_EQ(run("resumed", "partial.csv", said), full) << said;
  EXPECT_NE(said.find("(1 suites run"), std::string::npos) << said;
  EXPECT_EQ(validation_section(rocklab::test::read_file(dir / "resumed/report.md")), reference);
  EXPECT_EQ(rocklab::test::read_file(dir / "partial.csv"), all);
}

// A stage that runs some of the file's tests (elastic: the UCS) is served by the replicate of all
// of them at the same card and seed (each test runs on its own), here from the per-seed rows of a
// validation that ran every test: the campaign runs nothing.
TEST(SeedRows, TheUcsOfAReplicateOfEveryTestServesTheElasticStage) {
  const fs::path dir = rocklab::test::scratch_root() / "seed-rows-subset";
  fs::remove_all(dir);
  fs::create_directories(dir);
  nlohmann::json j = tiny_validation("rows.csv");
  j["targets"]["youngs_modulus_Pa"]["tolerance"] = 0.9; // met at the start: no step
  j["targets"].erase("ucs_Pa");
  j["parameters"]["flatjoint.fj_emod"] = {{"role", "modulus"}, {"bounds", {1e8, 1e12}}};
  j["tests"].push_back({{"name", "bz"},
                        {"test", "brazilian"},
                        {"shape", {{"shape", "disk"}, {"diameter", 0.02}}},
                        {"output", {{"vtk", false}, {"plots", false}}}});
  auto run = [&](const std::string& name, const nlohmann::json& cal, std::string& said) {
    const std::string file = (dir / (name + ".json")).string();
    std::ofstream(file) << cal.dump(2);
    return rocklab::test::run_command(rocklab::test::binary() + " calibrate " + file + " -o " +
                                          (dir / name).string() + " --jobs 1",
                                      &said);
  };
  std::string said;
  const int first = run("all-tests", j, said); // seed 1 and 2 fresh seeds, every test
  ASSERT_TRUE(first == 0 || first == 1) << said;
  j["budget"]["elastic"] = 1; // now an elastic stage (the UCS alone) before the final evaluation
  j["budget"]["max_seeds"] = 1;
  const int second = run("elastic", j, said);
  ASSERT_TRUE(second == 0 || second == 1) << said;
  EXPECT_NE(said.find("1 elastic:"), std::string::npos) << said;
  EXPECT_NE(said.find("1 seed(s), 1 cached"), std::string::npos) << said;
  EXPECT_NE(said.find("(0 suites run"), std::string::npos) << said;
}
