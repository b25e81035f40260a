// What a test's acoustic-emission events add up to: counts by source type and the b-value of
// their moment magnitudes (results.json "acoustic_emission"), and the magnitude-frequency plot.
// Units SI (times in s); magnitudes and b-values are dimensionless.
#pragma once

#include "lab/fractures.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace rocklab {

/// The "acoustic_emission" block of results.json: events with a source, their counts by class
/// (Feignier & Young), the moment magnitudes' range and the b-value (lab/b_value.hpp) over the
/// whole test and over the events up to `peak_time` [s] (NaN: not given).
nlohmann::json acoustic_emission_summary(const std::vector<FractureEvent>& events,
                                         double peak_time);

/// The printout's line on the acoustic emission (counts by source type, b-values).
void print_acoustic_emission(const nlohmann::json& summary);

/// An SVG of the magnitude-frequency distribution (cumulative counts N(M >= m) on a log scale,
/// and the non-cumulative counts per 0.1 bin) with the fitted Gutenberg-Richter line over
/// M >= Mc; "" when no event has a moment magnitude.
std::string magnitude_frequency_svg(const std::vector<FractureEvent>& events,
                                    const std::string& title);

/// A test's load curve for the acoustic-emission plot, one entry per reading.
struct LoadCurve {
  std::vector<double> time;       ///< [s]
  std::vector<double> strain_pct; ///< axial strain [%]
  std::vector<double> stress_mpa; ///< axial stress [MPa]
  std::string label, xlabel, ylabel;
};

/// The load curve with the acoustic emission against the axial strain: the event rate (per
/// fiftieth of the strain range, as a share of the busiest bin) and the cumulative event count
/// and moment (shares of the test's totals) on the right axis; "" without sources.
std::string acoustic_emission_svg(const LoadCurve& curve, const std::vector<FractureEvent>& events,
                                  const std::string& title);

} // namespace rocklab
