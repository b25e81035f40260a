// The defaults of a test in the loading frame: flat platens, not a disk, the standard post-peak
// stop rule, each declared suite property as gathered; the printout's tensile-strength line.
#include "lab/frame/frame_test.hpp"

#include "io/json_input.hpp"
#include "io/results.hpp"

#include <cstdio>

namespace rocklab {

std::unique_ptr<Actuator> FrameTest::actuator(const Protocol& p) const {
  return std::make_unique<Platens>(0.0, p.platen_friction.value_or(0.0)); // lubricated by default
}

void FrameTest::check_shape(const std::string& shape, const Protocol& p) const {
  if (shape == "disk")
    throw InputError(p.file + ": key 'specimen': a disk specimen is for Brazilian tests; give a "
                              "cylinder, prism or rectangle");
}

std::string FrameTest::stop_after_drop(LoadingFrame& f) {
  return load_fell_reason(f.protocol());
}

std::string load_fell_reason(const Protocol& p) {
  return "the load fell below " + format_double(p.post_peak_fraction) + " of its peak";
}

double SuiteValues::get(const std::string& name) const {
  const auto it = values.find(name);
  return it == values.end() ? std::nan("") : it->second;
}

void FrameTest::suite_results(const SuiteValues& v, nlohmann::json& props) const {
  for (const SuiteProperty& p : suite_properties())
    props[p.name] = number_or_null(v.get(p.name));
}

} // namespace rocklab
