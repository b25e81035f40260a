// The Gutenberg-Richter b-value of a set of event magnitudes: maximum likelihood above the
// magnitude of completeness, with its standard error. Magnitudes are dimensionless.
#pragma once

#include <vector>

namespace rocklab {

struct BValue {
  double b = 0;              ///< maximum-likelihood b (NaN: too few events) [-]
  double standard_error = 0; ///< Shi & Bolt (1982) [-]
  double completeness = 0;   ///< magnitude of completeness Mc (maximum curvature) [-]
  int events = 0;            ///< events at or above Mc [-]
};

/// Bin width of the frequency-magnitude distribution that the maximum-curvature Mc is read from.
constexpr double kMagnitudeBin = 0.1;
/// Fewest events at or above Mc for a b-value (fewer: b is NaN).
constexpr int kMinBValueEvents = 50;

/// Mc by maximum curvature (Wiemer & Wyss 2000): the lower edge of the kMagnitudeBin-wide bin
/// holding the most events. Then, over the magnitudes M >= Mc (taken as continuous),
/// b = log10(e) / (mean(M) - Mc) (Aki 1965) with standard error
/// 2.30 b^2 sqrt(sum (M - mean)^2 / (n (n - 1))) (Shi & Bolt 1982). Non-finite magnitudes are
/// left out.
BValue b_value(const std::vector<double>& magnitudes);

} // namespace rocklab
