// Triaxial compression: confining walls (a cylinder, or plates on the faces of a prism; 2D: a
// biaxial test) servo-controlled to loading.confinement, then the platens load the specimen; the
// peak deviator and the confinement band held (docs/protocol-format.md).
#include "lab/protocols/compression.hpp"

#include "io/json_input.hpp"
#include "lab/envelope.hpp"

namespace rocklab {

namespace {

class TriaxialTest final : public CompressionTest {
public:
  const char* name() const override { return "triaxial"; }
  void read_options(JsonObject& loading, JsonObject& stop, const Protocol& p) override {
    CompressionTest::read_options(loading, stop, p);
    confinement_ = loading.number("confinement", Range::non_negative(), 0.0, "Pa");
    if (!(confinement_ > 0))
      loading.fail("confinement", "a triaxial test needs a confining stress > 0 Pa");
    tolerance_ = loading.number("confinement_tolerance", {0, 0.5, true, false}, 0.01);
  }
  FrameSetup setup() const override {
    FrameSetup s = compression_setup();
    s.first_phase = kConfine;
    return s;
  }
  std::unique_ptr<ConfiningWalls> confinement() const override {
    return std::make_unique<ConfiningWalls>(confinement_, tolerance_);
  }
  // The strength envelope through the UCS and the triaxial peaks (Hoek-Brown needs two).
  std::vector<SuiteProperty> suite_properties() const override {
    using enum PropertyKind;
    constexpr const char* kMohrCoulomb =
        "{envelope_points} compression peak(s); Mohr-Coulomb needs 2 confinements";
    return {{.name = "friction_angle_deg",
             .label = "friction angle",
             .kind = Angle,
             .headline = 7,
             .detail = "(R2 {mohr_coulomb_r2})",
             .missing = kMohrCoulomb,
             .other = "ucs"},
            {.name = "cohesion_Pa",
             .label = "cohesion",
             .kind = Stress,
             .headline = 8,
             .missing = kMohrCoulomb,
             .other = "ucs"},
            {.name = "hoek_brown_mi",
             .label = "Hoek-Brown m_i",
             .headline = 9,
             .detail = "({envelope_points} points, sigma3 up to {envelope_sigma3_max_over_ucs} "
                       "UCS, fit error {hoek_brown_fit_error})",
             .missing = "{envelope_points} compression peak(s); Hoek-Brown needs 3",
             .count = 2,
             .other = "ucs"}};
  }
  // Mohr-Coulomb from two confinements on, Hoek-Brown from three (the UCS counts as one).
  void suite_results(const SuiteValues& v, nlohmann::json& props) const override {
    const auto points = [&](const char* key) {
      const auto it = v.series.find(key);
      return it == v.series.end() ? std::vector<double>{} : it->second;
    };
    const Envelope env = fit_envelope(points(kEnvelopeSigma3), points(kEnvelopeSigma1));
    const nlohmann::json none = nullptr;
    props["friction_angle_deg"] = env.has_mc ? number_or_null(env.friction_angle_deg) : none;
    props["cohesion_Pa"] = env.has_mc ? number_or_null(env.cohesion) : none;
    props["mohr_coulomb_r2"] = env.has_mc ? number_or_null(env.r2_mc) : none;
    props["hoek_brown_mi"] = env.has_hb ? number_or_null(env.hb_mi) : none;
    props["hoek_brown_sigma_c_Pa"] = env.has_hb ? number_or_null(env.hb_sigma_c) : none;
    props["envelope_points"] = env.points;
    // The range the envelope was fitted over: Hoek-Brown fits take sigma3 up to about half the
    // UCS (Hoek & Brown 1997); m_i from sigma3 <= 0.05 UCS is an extrapolation.
    props["envelope_sigma3_max_Pa"] = env.sigma3_max;
    props["envelope_sigma3_max_over_ucs"] = number_or_null(env.sigma3_max / v.get("ucs_Pa"));
    props["hoek_brown_fit_error"] = env.has_hb ? number_or_null(env.hb_fit_error) : none;
  }

private:
  double confinement_ = 0;  ///< loading.confinement [Pa]
  double tolerance_ = 0.01; ///< loading.confinement_tolerance: the confining phase's band [-]
};

} // namespace

std::unique_ptr<LabProtocol> make_triaxial_test() {
  return std::make_unique<TriaxialTest>();
}

} // namespace rocklab
