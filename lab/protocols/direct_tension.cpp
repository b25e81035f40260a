// Direct tension: grips hold the grains near both ends of the specimen and pull them apart at a
// constant rate; the tensile strength is the peak force over the initial section
// (docs/protocol-format.md).
#include "lab/frame/frame_test.hpp"
#include "lab/protocols/tensile_strength.hpp"

#include "io/json_input.hpp"
#include "io/results.hpp"
#include "lab/frame/elastic_fit.hpp"

namespace rocklab {

namespace {

class DirectTensionTest final : public FrameTest {
public:
  const char* name() const override { return "direct_tension"; }
  void read_options(JsonObject& loading, JsonObject&, const Protocol& p) override {
    grip_fraction_ = loading.number("grip_fraction", {0, 0.4, true, false}, 0.1);
    if (p.platen_friction)
      loading.fail("platen_friction", "a direct tension test has grips, not platens");
  }
  FrameSetup setup() const override {
    FrameSetup s;
    s.first_phase = kLoad;
    return s;
  }
  std::unique_ptr<Actuator> actuator(const Protocol&) const override {
    return std::make_unique<Grips>(grip_fraction_);
  }
  double axial_strain(const LoadingFrame& f) const override {
    return (f.separation() - f.sep_ref()) / f.geometry().height0; // elongation
  }
  void stresses(const LoadingFrame& f, LabSample& s) const override {
    s.axial_stress = s.force / f.geometry().area0;
    s.load = s.axial_stress;
  }
  void results(const LoadingFrame& f, nlohmann::json& r) const override {
    r["tensile_strength_Pa"] = f.peak().load;
    r["peak_force_N"] = f.peak().force;
    r["peak_axial_strain"] = f.peak().strain;
    r["youngs_modulus_Pa"] = fit_elastic(f.samples(), f.peak().load, 0.4, 0.6).youngs_modulus;
  }
  PlotLabels plot_labels() const override {
    return {"strain [%] (compression positive)", "tensile stress [MPa]", false, 1};
  }
  std::vector<SuiteProperty> result_columns() const override {
    return {{.name = "youngs_modulus_Pa", .label = "E", .kind = PropertyKind::Modulus},
            {.name = "tensile_strength_Pa", .label = "tensile", .kind = PropertyKind::Stress}};
  }
  std::vector<SuiteProperty> suite_properties() const override {
    return {{.name = "direct_tension_Pa",
             .label = "direct tension",
             .kind = PropertyKind::Stress,
             .headline = 5},
            {.name = "direct_tension_over_bts",
             .label = "DT/BTS",
             .valid_share = "brazilian_valid",
             .other = "brazilian"}};
  }
  void add_to_suite(const nlohmann::json& r, SuiteValues& v) const override {
    if (!v.has("direct_tension_Pa"))
      v.values["direct_tension_Pa"] = json_number(r, "tensile_strength_Pa", std::nan(""));
  }
  void suite_results(const SuiteValues& v, nlohmann::json& props) const override {
    FrameTest::suite_results(v, props); // the strength as gathered; its ratio to the BTS below
    props["direct_tension_over_bts"] = number_or_null(v.get("direct_tension_Pa") / v.get("bts_Pa"));
  }
  void print_results(const nlohmann::json& r) const override {
    if (r["tensile_strength_Pa"].is_number())
      print_tensile_strength(r);
  }

private:
  double grip_fraction_ = 0.1; ///< loading.grip_fraction: grips hold grains this near an end
};

} // namespace

std::unique_ptr<LabProtocol> make_direct_tension_test() {
  return std::make_unique<DirectTensionTest>();
}

} // namespace rocklab
