// What the compression tests (UCS and triaxial) share: the axial strain of the platens, the axial
// stress over the current section and the deviator as the load, the elastic constants, the
// confinement band and the loading/unloading moduli in results.json, and the plot with the
// lateral strain. Units SI.
#pragma once

#include "lab/frame/frame_test.hpp"
#include "lab/protocols/curve_analysis.hpp"

namespace rocklab {

/// The suite series of the compression tests' confinements and peak stresses [Pa].
inline constexpr const char* kEnvelopeSigma3 = "envelope_sigma3_Pa";
inline constexpr const char* kEnvelopeSigma1 = "envelope_sigma1_Pa";

class CompressionTest : public FrameTest {
public:
  /// loading.reverse_at_strain: > 0 unloads from this axial strain back to zero (elastic test).
  void read_options(JsonObject& loading, JsonObject& stop, const Protocol& p) override;
  double axial_strain(const LoadingFrame& f) const override;
  void stresses(const LoadingFrame& f, LabSample& s) const override;
  void results(const LoadingFrame& f, nlohmann::json& r) const override;
  PlotLabels plot_labels() const override;
  /// The peak, the elastic constants and the crack stresses, then the confinement band.
  void print_results(const nlohmann::json& r) const override;
  /// The crack-initiation and crack-damage stresses on the axial curve.
  void plot_markers(const std::vector<LabSample>& samples, const nlohmann::json& r,
                    std::vector<PlotMarker>& m) const override;
  /// The confinement, E, nu, the peak stress and deviator.
  std::vector<SuiteProperty> result_columns() const override;
  /// A point (confinement, peak stress) of the strength envelope.
  void add_to_suite(const nlohmann::json& r, SuiteValues& v) const override;

  /// The loading branch up to the peak with the crack count at each sample.
  static CurveInput curve(const LoadingFrame& f);

protected:
  /// The frame set-up of a compression test with its options (unconfined, seated first).
  FrameSetup compression_setup() const;
  double reverse_at_strain_ = 0; ///< loading.reverse_at_strain [-]
};

} // namespace rocklab
