// Uniaxial compression (UCS): lubricated platens close on an unconfined cylinder or prism (2D: a
// rectangle) at a constant rate after seating; E and nu from the pre-peak curve, the UCS at the
// peak (docs/protocol-format.md).
#include "lab/protocols/compression.hpp"

#include "io/results.hpp"

namespace rocklab {

namespace {

class UcsTest final : public CompressionTest {
public:
  const char* name() const override { return "ucs"; }
  FrameSetup setup() const override { return compression_setup(); }
  std::vector<SuiteProperty> suite_properties() const override {
    using enum PropertyKind;
    return {{.name = "youngs_modulus_Pa",
             .label = "E",
             .kind = Modulus,
             .headline = 1,
             .role = CalibrationRole::Modulus},
            {.name = "poisson_ratio",
             .label = "nu",
             .headline = 2,
             .role = CalibrationRole::StiffnessRatio},
            {.name = "ucs_Pa",
             .label = "UCS",
             .kind = Stress,
             .headline = 3,
             .role = CalibrationRole::Strength},
            {.name = "crack_initiation_over_ucs",
             .label = "CI/UCS",
             .method = "crack volumetric strain (Martin & Chandler 1994), as laboratory cores are "
                       "read; crack_initiation_count_over_ucs: the crack count onset"},
            {.name = "ucs_over_bts",
             .label = "UCS/BTS",
             .headline = 6,
             .valid_share = "brazilian_valid",
             .other = "brazilian"}};
  }
  // The first UCS test gives E, nu, the UCS and the crack-initiation stresses. The laboratory's
  // crack initiation is read from the stress-strain curves (Nicksiar & Martin 2013: 376 tests,
  // CI/peak 0.42-0.47), so the summary's ratio is the strain-based one; the crack-count onset,
  // which no laboratory measures, is beside it.
  void add_to_suite(const nlohmann::json& r, SuiteValues& v) const override {
    CompressionTest::add_to_suite(r, v);
    if (v.has("ucs_Pa"))
      return;
    auto num = [&](const char* key) { return json_number(r, key, std::nan("")); };
    v.values["ucs_Pa"] = num("peak_stress_Pa");
    v.values["youngs_modulus_Pa"] = num("youngs_modulus_Pa");
    v.values["poisson_ratio"] = num("poisson_ratio");
    v.values["crack_initiation_stress_Pa"] = num("crack_initiation_stress_volumetric_Pa");
    v.values["crack_initiation_count_stress_Pa"] = num("crack_initiation_stress_Pa");
  }
  void suite_results(const SuiteValues& v, nlohmann::json& props) const override {
    CompressionTest::suite_results(v, props); // E, nu and the UCS as gathered; ratios below
    const double ucs = v.get("ucs_Pa"), ci = v.get("crack_initiation_stress_Pa");
    props["ucs_over_bts"] = number_or_null(ucs / v.get("bts_Pa"));
    props["crack_initiation_stress_Pa"] = number_or_null(ci);
    props["crack_initiation_over_ucs"] = number_or_null(ci / ucs);
    props["crack_initiation_count_over_ucs"] =
        number_or_null(v.get("crack_initiation_count_stress_Pa") / ucs);
  }
};

} // namespace

std::unique_ptr<LabProtocol> make_ucs_test() {
  return std::make_unique<UcsTest>();
}

} // namespace rocklab
