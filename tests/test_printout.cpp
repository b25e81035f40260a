// Each test in the frame supplies its own printout lines and plot markers (issue 41): the generic
// printout and plot know no test by name; the suite properties they declare are the summary keys
// and calibration targets. Results are synthetic JSON, as results.json has them.
#include "lab/calibration/calibration_file.hpp"
#include "lab/frame/frame_test.hpp"
#include "lab/protocol_table.hpp"
#include "lab/suite.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace rocklab;
using nlohmann::json;

namespace {

std::string printed(const FrameTest& t, const json& r) {
  testing::internal::CaptureStdout();
  t.print_results(r);
  return testing::internal::GetCapturedStdout();
}

} // namespace

TEST(Printout, ABrazilianTestPrintsAndMarksItsStrengthBeforeTheSplit) {
  const auto t = make_frame_test("brazilian");
  ASSERT_TRUE(t);
  json r = {{"tensile_strength_Pa", 8.5e6},
            {"peak_force_N", 1234.0},
            {"peak_axial_strain", 0.002},
            {"split",
             {{"stress_Pa", 8.5e6},
              {"peak_Pa", 9.75e6},
              {"tension_lost_step", 100},
              {"peak_step", 200}}}};
  EXPECT_EQ(printed(*t, r), "tensile strength 8.5 MPa (force 1234 N) before the split released the "
                            "diametral tension; the halves then carried up to 9.75 MPa\n");
  std::vector<PlotMarker> m;
  t->plot_markers({}, r, m);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_DOUBLE_EQ(m[0].x, 0.2);
  EXPECT_DOUBLE_EQ(m[0].y, 8.5);
  EXPECT_EQ(m[0].label, "tensile strength (before the split)");
  // The strength at the peak: no clause and no marker.
  r["split"]["stress_Pa"] = 9.75e6;
  r["split"]["tension_lost_step"] = -1;
  r["tensile_strength_Pa"] = 9.75e6;
  EXPECT_EQ(printed(*t, r), "tensile strength 9.75 MPa (force 1234 N)\n");
  m.clear();
  t->plot_markers({}, r, m);
  EXPECT_TRUE(m.empty());
  // No split: no strength.
  r["tensile_strength_Pa"] = nullptr;
  EXPECT_EQ(printed(*t, r),
            "tensile strength not measured (no split); 2F/(pi D t) peaked at 9.75 MPa\n");
  // The split check off: the peak, and no split record.
  r.erase("split");
  r["tensile_strength_Pa"] = 7e6;
  EXPECT_EQ(printed(*t, r), "tensile strength 7 MPa (force 1234 N)\n");
}

TEST(Printout, TriaxialPrintsItsConfinementAndTheOthersTheirOwnLinesOnly) {
  // The compression tests print the peak, E and nu (the block the generic printout used to print
  // for any test), a triaxial its confinement band after them; a tension test its strength only.
  const json peak = {{"peak_stress_Pa", 2e8},
                     {"peak_deviator_Pa", 1.95e8},
                     {"peak_axial_strain", 0.003},
                     {"youngs_modulus_Pa", 7e10},
                     {"poisson_ratio", 0.25}};
  json confined = peak;
  confined["confinement_Pa"] = 5e6;
  confined["confinement_measured_Pa"] = {{"min", 4.9e6}, {"max", 5.1e6}};
  const std::string block = "peak stress  200 MPa (deviator 195 MPa) at axial strain 0.3 %\n"
                            "E            70 GPa over the linear window, not measured secant at "
                            "50 % of peak   poisson 0.250\n";
  EXPECT_EQ(printed(*make_frame_test("triaxial"), confined),
            block + "confinement  5 MPa (held between 4.9 and 5.1 MPa)\n");
  json unconfined = peak;
  unconfined["confinement_Pa"] = 0.0;
  EXPECT_EQ(printed(*make_frame_test("ucs"), unconfined), block);
  EXPECT_EQ(printed(*make_frame_test("direct_tension"),
                    {{"tensile_strength_Pa", 3e6}, {"peak_force_N", 50.0}}),
            "tensile strength 3 MPa (force 50 N)\n");
  for (const char* name : {"ucs", "triaxial", "direct_tension"}) {
    std::vector<PlotMarker> m;
    make_frame_test(name)->plot_markers({}, confined, m);
    EXPECT_TRUE(m.empty()) << name;
  }
}

TEST(Printout, ACompressionTestMarksItsCrackStressesOnTheAxialCurve) {
  // The crack stresses are the compression test's markers, placed at the axial stress of the
  // first reading at their strain (the generic plot code placed them before).
  std::vector<LabSample> samples(3);
  for (int k = 0; k < 3; ++k) {
    samples[k].axial_strain = 0.001 * (k + 1);
    samples[k].axial_stress = 5e7 * (k + 1);
  }
  const json r = {{"crack_initiation_stress_Pa", 9e7},
                  {"crack_initiation_stress_volumetric_Pa", nullptr},
                  {"crack_damage_stress_Pa", 1.4e8},
                  {"crack_stresses",
                   {{"crack_initiation_axial_strain", 0.0015},
                    {"crack_initiation_volumetric_axial_strain", nullptr},
                    {"crack_damage_axial_strain", 0.003}}}};
  std::vector<PlotMarker> m;
  make_frame_test("ucs")->plot_markers(samples, r, m);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_DOUBLE_EQ(m[0].x, 0.15);
  EXPECT_DOUBLE_EQ(m[0].y, 100);
  EXPECT_EQ(m[0].label, "CI (crack count)");
  EXPECT_DOUBLE_EQ(m[1].y, 150);
  EXPECT_EQ(m[1].label, "CD (volume reversal)");
}

TEST(Printout, EveryDeclaredSuitePropertyIsASummaryKeyAndACalibrationTarget) {
  // A property a test declares reaches summary.json (null until measured) and the calibration's
  // targets with that test as the one that measures it: no second name table to edit.
  int declared = 0;
  for (const std::string& name : frame_test_names()) {
    const auto t = make_frame_test(name);
    json props = json::object();
    t->suite_results(SuiteValues{}, props);
    for (const SuiteProperty& p : t->suite_properties()) {
      ++declared;
      EXPECT_TRUE(props.contains(p.name)) << name << " " << p.name;
      EXPECT_TRUE(props[p.name].is_null()) << p.name;
      bool target = false;
      for (const calibration::TargetNeed& n : calibration::target_needs())
        target = target || (std::string(n.property) == p.name && n.test == name);
      EXPECT_TRUE(target) << p.name;
    }
  }
  EXPECT_EQ(static_cast<std::size_t>(declared), calibration::target_needs().size());
  EXPECT_EQ(std::string(calibration::target_needs().front().property), "youngs_modulus_Pa");
}

TEST(Printout, EveryDeclaredSuitePropertyIsAColumnOfTheSuiteTables) {
  // summary.csv and the printed suite table list a property a test declares without an edit of
  // their own: the headline first (by their declared place), then the others; each printed with
  // its label and in its kind's unit.
  const std::vector<std::string> cols = summary_columns();
  ASSERT_GE(cols.size(), 9u);
  EXPECT_EQ(cols[0], "youngs_modulus_Pa");
  EXPECT_EQ(cols[2], "ucs_Pa");
  EXPECT_EQ(cols[8], "hoek_brown_mi");
  json props = {{"envelope_points", 3}, {"mohr_coulomb_r2", 0.99}};
  for (const DeclaredProperty& d : declared_properties()) {
    EXPECT_NE(std::find(cols.begin(), cols.end(), d.p.name), cols.end()) << d.p.name;
    EXPECT_TRUE(d.p.label) << d.p.name << ": every declared property has a label";
    props[d.p.name] = 1.5;
  }
  const json summary = {
      {"suite", "s"}, {"material", "m"}, {"tests", json::array()}, {"properties", props}};
  const std::string table = summary_table(summary);
  for (const DeclaredProperty& d : declared_properties())
    EXPECT_NE(table.find(property_text(d.p, props)), std::string::npos) << d.p.name << "\n"
                                                                        << table;
  EXPECT_NE(table.find("E 1.5e-09 GPa   nu 1.5   UCS 1.5e-06 MPa   BTS 1.5e-06 MPa"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("CI/UCS 1.5"), std::string::npos) << table;
  // No valid disk: the BTS is not measured, and what the disks that were not valid read is said as
  // such, not as the BTS.
  json invalid = summary;
  invalid["properties"]["bts_Pa"] = nullptr;
  invalid["properties"]["ucs_over_bts"] = nullptr;
  invalid["properties"]["bts_not_valid_Pa"] = 11.21e6;
  const std::string no_bts = summary_table(invalid);
  EXPECT_NE(no_bts.find("BTS not measured (no valid disk; the disks not valid read 11.21 MPa)"),
            std::string::npos)
      << no_bts;
  EXPECT_NE(no_bts.find("UCS/BTS -"), std::string::npos) << no_bts;
  // The envelope's m_i comes with the sigma3 range it was fitted over and its fit error.
  EXPECT_NE(table.find("(3 points, sigma3 up to - UCS, fit error -)"), std::string::npos) << table;
  json fitted = summary;
  fitted["properties"]["envelope_sigma3_max_over_ucs"] = 0.25;
  fitted["properties"]["hoek_brown_fit_error"] = 0.156;
  EXPECT_NE(summary_table(fitted).find(
                "Hoek-Brown m_i 1.5 (3 points, sigma3 up to 0.25 UCS, fit error 0.156)"),
            std::string::npos)
      << summary_table(fitted);
  // A suite without triaxial tests has no envelope: its properties say why, not a row of dashes.
  json bare = summary;
  bare["properties"]["envelope_points"] = 1;
  for (const char* k : {"friction_angle_deg", "cohesion_Pa", "hoek_brown_mi"})
    bare["properties"][k] = nullptr;
  const std::string none = summary_table(bare);
  EXPECT_NE(none.find("friction angle not measured (1 compression peak(s); Mohr-Coulomb needs 2 "
                      "confinements)"),
            std::string::npos)
      << none;
  EXPECT_NE(none.find("Hoek-Brown m_i not measured (1 compression peak(s); Hoek-Brown needs 3)"),
            std::string::npos)
      << none;
}

TEST(Printout, ATestsColumnsAreItsDeclaredResultKeys) {
  // tests.csv's header and the printed per-test table come from the tests' result columns.
  const json row = {{"name", "disk"},
                    {"test", "brazilian"},
                    {"status", "ok"},
                    {"tensile_strength_Pa", 9.3e6},
                    {"cracks", {{"total", 42}}},
                    {"wall_time_s", 12.34}};
  const json summary = {
      {"suite", "s"}, {"material", "m"}, {"tests", {row}}, {"properties", json::object()}};
  const std::string t = summary_table(summary);
  EXPECT_NE(t.find("tensile [MPa]"), std::string::npos) << t;
  EXPECT_NE(t.find("9.3 "), std::string::npos) << t;
  EXPECT_NE(t.find("42"), std::string::npos) << t;
  EXPECT_NE(t.find("12.3"), std::string::npos) << t;
  EXPECT_NE(t.find("conf [MPa]"), std::string::npos) << t;
}

TEST(Printout, ACrackStressNoCrackMarkedReadsNotMeasuredNotZero) {
  // A UCS without cracks before the peak (the 2D contact-bonded Berea to 2 % strain) has null
  // crack stresses in results.json; the printout said "0 MPa (0.00 of peak)".
  LabSummary s;
  s.results = {
      {"test", "ucs"},
      {"provenance", {{"material", "card"}, {"grains", 10}, {"steps", 100}}},
      {"peak_stress_Pa", 2e8},
      {"peak_deviator_Pa", 2e8},
      {"peak_axial_strain", 0.003},
      {"youngs_modulus_Pa", 7e10},
      {"crack_initiation_stress_Pa", nullptr},
      {"crack_initiation_stress_volumetric_Pa", nullptr},
      {"crack_damage_stress_Pa", nullptr},
      {"crack_stresses", {{"crack_initiation_ratio", nullptr}, {"crack_damage_ratio", nullptr}}},
      {"cracks", {{"tension", 0}, {"shear", 0}, {"at_peak", {{"total", 0}}}}},
      {"stop_reason", "stop.strain_limit reached"},
      {"files", json::array()}};
  const auto t = make_frame_test("ucs");
  auto line = [&] {
    testing::internal::CaptureStdout();
    t->print(s, "out");
    const std::string all = testing::internal::GetCapturedStdout();
    const auto a = all.find("crack stress");
    return a == std::string::npos ? all : all.substr(a, all.find('\n', a) - a);
  };
  EXPECT_EQ(line(),
            "crack stress initiation not measured, volumetric not measured; damage not measured");
  s.results["crack_initiation_stress_Pa"] = 9e7;
  s.results["crack_initiation_stress_volumetric_Pa"] = 8e7;
  s.results["crack_damage_stress_Pa"] = 1.5e8;
  s.results["crack_stresses"] = {{"crack_initiation_ratio", 0.45}, {"crack_damage_ratio", 0.75}};
  EXPECT_EQ(line(), "crack stress initiation 90 MPa (0.45 of peak), volumetric 80 MPa; damage "
                    "150 MPa (0.75 of peak)");
}

TEST(Printout, AToyTestsPropertyReachesEveryTableFromItsOwnFile) {
  // tests/fixtures/toy_point_load.cpp: a test file and its registration line, nothing else.
  const auto names = frame_test_names();
  ASSERT_NE(std::find(names.begin(), names.end(), "toy_point_load"), names.end());
  const auto t = make_frame_test("toy_point_load");
  const json r = {{"point_load_index_Pa", 4.2e6}};
  EXPECT_EQ(printed(*t, r), "point load index 4.2 MPa\n"); // the printout
  const auto cols = tests_csv_columns();                   // tests.csv
  EXPECT_NE(std::find(cols.begin(), cols.end(), "point_load_index_Pa"), cols.end());
  const auto sum = summary_columns(); // summary.csv
  EXPECT_NE(std::find(sum.begin(), sum.end(), "point_load_index_Pa"), sum.end());
  json row = {{"name", "pl"},
              {"test", "toy_point_load"},
              {"status", "ok"},
              {"point_load_index_Pa", 4.2e6},
              {"cracks", {{"total", 3}}},
              {"wall_time_s", 1.0}};
  const json summary = {{"suite", "s"},
                        {"material", "m"},
                        {"tests", {row}},
                        {"properties", {{"point_load_index_Pa", 4.2e6}}}};
  const std::string table = summary_table(summary); // the suite table: column and property
  EXPECT_NE(table.find("Is [MPa]"), std::string::npos) << table;
  EXPECT_NE(table.find("Is 4.2 MPa"), std::string::npos) << table;
  bool target = false; // a calibration target, measured by the toy test
  for (const calibration::TargetNeed& n : calibration::target_needs())
    target = target || (std::string(n.property) == "point_load_index_Pa" &&
                        std::string(n.test) == "toy_point_load");
  EXPECT_TRUE(target);
  // and a suite's summary.json gathers it through the test's own add_to_suite.
  SuiteValues v;
  t->add_to_suite(r, v);
  json props = json::object();
  t->suite_results(v, props);
  EXPECT_DOUBLE_EQ(props["point_load_index_Pa"].get<double>(), 4.2e6);
}
