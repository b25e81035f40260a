// Brazilian (indirect tension) test: a disk between flat platens that keep the specimen's wall
// friction, loaded across its diameter; the tensile strength is 2F / (pi D t) at the peak. The
// test ends only when the disk has split: cracks within 0.2 D of the loaded diameter cover
// stop.split_fraction of it in one unbroken run of tenths, or the load collapses below
// stop.failed_fraction of its peak without a split (docs/protocol-format.md).
#include "lab/protocols/frame_test.hpp"

#include "io/json_fields.hpp"
#include "io/json_input.hpp"
#include "io/results.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace rocklab {

namespace {

class BrazilianTest final : public FrameTest {
public:
  const char* name() const override { return "brazilian"; }
  FrameSetup setup() const override {
    FrameSetup s;
    s.diametral = true;
    s.platen_friction = true;
    return s;
  }
  void check_stop(JsonObject&) const override {} // split_fraction and failed_fraction apply
  void check_shape(const std::string& shape, const Protocol& p) const override {
    if (shape != "disk")
      throw InputError(
          p.file + ": key 'specimen': a Brazilian test needs a disk specimen, not " +
          (shape.empty() ? std::string("a specimen without a genesis record") : "a " + shape) +
          "; give \"shape\": {\"shape\": \"disk\", ...}");
  }
  double axial_strain(const LoadingFrame& f) const override {
    return (f.sep_ref() - f.separation()) / f.geometry().width0.y(); // displacement / D
  }
  void stresses(const LoadingFrame& f, LabSample& s) const override {
    // Tensile stress at the disk centre: 2F / (pi D t); 2D: F per unit thickness, t = 1.
    const SpecimenGeometry& g = f.geometry();
    s.axial_stress = 2 * s.force / (std::numbers::pi * g.width0.x() * g.thickness);
    s.load = s.axial_stress;
  }
  std::string stop_after_drop(const LoadingFrame& f) override {
    // A disk can lose load locally (a grain crushed under a platen) and reload; only a split
    // along the loaded diameter ends the test, or a load collapse below failed_fraction.
    const Protocol& p = f.protocol();
    if (p.split_fraction <= 0)
      return load_fell_reason(p);
    if (split_seen(f))
      return "the disk split and the load fell below " + format_double(p.post_peak_fraction) +
             " of its peak";
    if (f.current().load < p.failed_fraction * f.peak().load)
      return "the load fell below " + format_double(p.failed_fraction) +
             " of its peak without a split along the loaded diameter";
    return "";
  }
  void results(const LoadingFrame& f, nlohmann::json& r) const override {
    const Protocol& p = f.protocol();
    if (p.split_fraction > 0)
      r["split"] = {{"found", split_step_ >= 0},
                    {"step", split_step_},
                    {"fraction_required", p.split_fraction}};
    r["tensile_strength_Pa"] = f.peak().load;
    r["peak_force_N"] = f.peak().force;
    r["peak_axial_strain"] = f.peak().strain;
  }
  PlotLabels plot_labels() const override {
    return {"platen displacement / D [%]", "2F / (pi D t) [MPa]", false, 2};
  }
  void save(nlohmann::json& state) const override { state["split_step"] = split_step_; }
  void load(const nlohmann::json& state, const std::string& file) override {
    JsonFieldReader r{state, file};
    r("split_step", split_step_);
    bins_.fill(false);
    scanned_ = 0; // rebinned from the restored cracks at the next check
  }

private:
  // Cracks within 0.2 D of the loaded diameter (the y axis through the centre), binned by their
  // position along it; a split covers split_fraction of the ten bins without a gap.
  bool split_seen(const LoadingFrame& f) {
    const double d = f.geometry().width0.y();
    const auto& cracks = f.cracks().cracks();
    for (; scanned_ < cracks.size(); ++scanned_) {
      const Crack& c = cracks[scanned_];
      const Vec3 rel = c.position - f.geometry().center;
      if (std::abs(rel.x()) > 0.2 * d)
        continue;
      const double t = (rel.y() + 0.5 * d) / d;
      const int bin = std::clamp(static_cast<int>(std::floor(t * 10.0)), 0, 9);
      bins_[static_cast<std::size_t>(bin)] = true;
    }
    // The longest unbroken run of cracked tenths: crushing under both platens covers the two
    // ends of the diameter but not the middle, a split covers it continuously.
    int run = 0, longest = 0;
    for (bool b : bins_) {
      run = b ? run + 1 : 0;
      longest = std::max(longest, run);
    }
    const bool split =
        longest >= static_cast<int>(std::ceil(f.protocol().split_fraction * 10.0 - 1e-9));
    if (split && split_step_ < 0)
      split_step_ = f.model().step();
    return split;
  }

  std::array<bool, 10> bins_{};  ///< which tenths of the loaded diameter hold a crack near it
  std::size_t scanned_ = 0;      ///< cracks already binned (rebuilt from the cracks on resume)
  std::int64_t split_step_ = -1; ///< first stop check (after the drop) that saw the split
};

} // namespace

std::unique_ptr<LabProtocol> make_brazilian_test() {
  return std::make_unique<BrazilianTest>();
}

} // namespace rocklab
