// Genesis before it starts: how many grains the card asks for, the memory and time that takes,
// and the cards that cannot finish (a specimen narrower than two grains, more grains than memory
// holds, an installation strain below what positions resolve, a bonding gap wider than a grain),
// refused with the key that says so (exit 2) instead of cycling or allocating without bound.
#include "contact/linear.hpp"
#include "materials/genesis/stages.hpp"

#include "io/input_error.hpp"
#include "io/work_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab::genesis {

namespace {

// Memory per grain: twice the peak resident set above the program's own 16.5 MB measured on
// genesis of granite_fj_2d at 50 x 100 mm (4,533 grains, 42.3 MB: 5.7 kB each) and of
// granite_fj_3d (1,670 grains, 41.2 MB: 14.8 kB each) [bytes].
constexpr double kBytesPerGrain2D = 12e3;
constexpr double kBytesPerGrain3D = 30e3;
// Work per grain and cycle on one core and the cycles a preset's genesis takes, for the printed
// estimate only, measured on the quiet 2-core machine (2026-12-07): granite_fj_2d, 1,126 grains,
// 156,600 cycles in 28.4 s; granite_fj_3d (the main job's cylinder), 1,643 grains, about 111,000
// cycles in about 100 s (the earlier figures, 0.32 and 1.1 us at 2e5 cycles, were 2.6 and 3.7
// times the time genesis takes now).
constexpr double kSecondsPerGrainCycle2D = 0.16e-6;
constexpr double kSecondsPerGrainCycle3D = 0.55e-6;
constexpr double kTypicalCycles2D = 1.6e5;
constexpr double kTypicalCycles3D = 1.1e5;
// Ball indices are 32-bit (contact adjacency stores index*2 + side).
constexpr double kMaxGrains = 1e8;
// The installation pressure over the grains' modulus below which the overlap it causes (this
// strain times a radius) is lost in the rounding of positions (double, ~1e-16 of the specimen).
constexpr double kMinInstallStrain = 1e-10;
constexpr double kMaxInstallStrain = 0.05;

std::string num(double v) {
  return message_number(v, 4);
}

double smallest_dimension(const ShapeSpec& s) {
  switch (s.shape) {
  case SpecimenShape::Rectangle:
    return std::min(s.size.x(), s.size.y());
  case SpecimenShape::Disk2D:
    return s.size.x();
  case SpecimenShape::Prism:
    return s.size.minCoeff();
  case SpecimenShape::Cylinder:
  case SpecimenShape::Disk3D:
    return std::min(s.size.x(), s.size.y());
  }
  return 0;
}

// Mean grain volume (area in 2D) by number: uniform radii, or the sieve's mass fractions spread
// over each interval's mid diameter.
double grains_in(const MaterialCard& c, double solid) {
  if (c.sieve.empty()) {
    const double a = c.r_min, b = c.r_max, d = c.dim;
    const double mean_rd =
        b > a ? (std::pow(b, d + 1) - std::pow(a, d + 1)) / ((d + 1) * (b - a)) : std::pow(a, d);
    return solid / (grain_volume(c.dim, 1.0) * mean_rd);
  }
  double n = 0;
  for (std::size_t k = 1; k < c.sieve.size(); ++k) {
    const double df = c.sieve[k].second - c.sieve[k - 1].second;
    const double d_mid = 0.5 * (c.sieve[k].first + c.sieve[k - 1].first);
    n += df * solid / grain_volume(c.dim, 0.5 * d_mid);
  }
  return n;
}

// The specimen's shape may come from a protocol, a suite, a calibration or the command line: the
// error names where it was given.
[[noreturn]] void refuse(const MaterialCard& c, const std::string& key, const std::string& what) {
  const bool vessel = key == "specimen" && !c.vessel_file.empty();
  throw InputError((vessel ? c.vessel_file : c.file) + ": key '" + (vessel ? c.vessel_key : key) +
                   "': " + what);
}

void check_shape(const MaterialCard& c, const ShapeSpec& s, const std::string& key) {
  const double across = smallest_dimension(s), need = 4 * c.r_max;
  if (!(across >= need))
    refuse(c, key,
           "its smallest dimension " + num(across) +
               " m holds fewer than two of the largest grains across; allowed: at least 4 R_max "
               "= " +
               num(need) + " m (or smaller grains)");
}

} // namespace

GenesisEstimate estimate_genesis(const MaterialCard& c) {
  GenesisEstimate e;
  if (!c.packing_import.empty())
    return e; // the file's grains: its size bounds the work
  check_shape(c, c.vessel, "specimen");
  if (c.cut)
    check_shape(c, *c.cut, "cut");
  const double r_avg = 0.5 * (c.r_min + c.r_max);
  if (c.install_gap > r_avg)
    refuse(c, c.install_gap_ratio >= 0 ? "installation.gap_ratio" : "installation.gap",
           "an installation gap of " + num(c.install_gap) + " m bonds grains farther apart than " +
               "a mean radius (" + num(r_avg) + " m), past their neighbours; allowed: up to " +
               "R_avg (gap_ratio <= 1)");
  e.grains = grains_in(c, c.vessel.volume(c.dim) * (1 - c.porosity));
  e.bytes = e.grains * (c.dim == 2 ? kBytesPerGrain2D : kBytesPerGrain3D);
  e.seconds = e.grains * (c.dim == 2 ? kTypicalCycles2D * kSecondsPerGrainCycle2D
                                     : kTypicalCycles3D * kSecondsPerGrainCycle3D);
  const double ram = physical_memory();
  if (e.grains > kMaxGrains || (ram > 0 && e.bytes > 0.8 * ram))
    refuse(c, "specimen",
           "the specimen holds about " + num(e.grains) + " grains of radius " + num(c.r_min) + "-" +
               num(c.r_max) + " m, needing about " + num(e.bytes / 1e9) + " GB; allowed: at most " +
               num(kMaxGrains) + " grains within 80 % of this machine's " + num(ram / 1e9) +
               " GB (a smaller specimen or larger grains)");
  // The installation pressure over the grains' modulus (2D: per unit thickness).
  const double area = linear::deformability_area(c.dim, r_avg);
  const double modulus = c.linear.emod > 0 ? c.linear.emod : c.linear.kn * 2 * r_avg / area;
  const double strain = c.pressure / modulus;
  const std::string mkey = c.linear.emod > 0 ? "linear.emod" : "linear.kn";
  if (!(strain >= kMinInstallStrain) || !(strain <= kMaxInstallStrain))
    refuse(c, "installation.pressure",
           num(c.pressure) + " Pa over the grains' modulus " + num(modulus) + " Pa (key '" + mkey +
               "') is a strain of " + num(strain) + "; allowed: " + num(kMinInstallStrain) +
               " to " + num(kMaxInstallStrain) +
               " (below, the grains' overlap is lost in the rounding of positions; above, " +
               "they overlap by more than the contact law holds)");
  return e;
}

} // namespace rocklab::genesis
