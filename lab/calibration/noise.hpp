// The seed noise of a calibration (docs/calibration.md, "Noise"): each measured target is a mean
// over packing seeds, so it carries a standard error; how many seeds a target needs for that error
// to be small against its tolerance; and what the noise leaves of the fitted micro-parameters
// (their uncertainty, and which the targets do not determine at all). Units SI; the
// uncertainties are relative (of ln parameter).
#pragma once

#include "lab/calibration/stages.hpp"

#include <cstdint>
#include <vector>

namespace rocklab::calibration {

/// The standard error of a mean of `n` seeds whose sample standard deviation is `sd`; NaN for
/// fewer than two seeds (one seed says nothing about the scatter).
double standard_error(double sd, int n);

/// A target's tolerance in its own units: a relative tolerance times |target|.
double tolerance_in_units(const Target& t);

/// The seeds a mean needs for its standard error to be at most `fraction` of the target's
/// tolerance, from the seed-to-seed standard deviation `sd`: ceil((sd / (fraction x
/// tolerance))^2), at least 2; -1 when sd is not known (NaN).
int seeds_needed(const Target& t, double sd, double fraction = 0.5);

/// The validation seeds a campaign runs: enough for every target's standard error to be at most
/// half its tolerance (from the seed-to-seed sd of the tuned seeds; a target whose sd is not
/// known, NaN, asks for the most), at least `min_seeds`, at most `max_seeds` (what is
/// affordable: the report names the targets that would need more).
int validation_seed_count(const std::vector<Target>& targets, const Measured& sd, int min_seeds,
                          int max_seeds);

/// The seed-to-seed sd of each property where its standard error is known (two seeds or more
/// measured it), NaN elsewhere: one seed says nothing about the scatter (its sd reads 0).
Measured known_scatter(const Measured& sd, const Measured& se);

/// Fresh seeds: `count` seeds from `first` on that are not among `used`.
std::vector<std::uint64_t> fresh_seeds(std::uint64_t first, int count,
                                       const std::vector<std::uint64_t>& used);

/// A step of a steered target that is within the noise: |measured - target| is below twice the
/// standard error of the measured mean (a step there would chase the packings' scatter).
bool within_noise(const Target& t, double measured, double se);

/// What the seed noise leaves of one fitted parameter.
struct ParamUncertainty {
  /// Standard deviation of ln(parameter) (about the relative sd for small values); infinite when
  /// not identifiable.
  double sd_ln = 0;
  /// Share of the parameter's direction in the targets' blind directions (combinations of
  /// parameters that move no target), 0..1.
  double blind_share = 0;
  bool identifiable = true; ///< blind_share below 0.1 and sd_ln at most 0.5
};

/// The linearised least-squares uncertainty of ln(parameters) from the sensitivity table
/// s[parameter][target] = d ln(target) / d ln(parameter) and each target's relative standard
/// error rel_se[target] = se / |mean|: the pseudo-inverse of J^T W J with J[target][parameter] =
/// s[parameter][target] and W = diag(1 / rel_se^2) (Gauss-Newton covariance). Targets with a NaN
/// sensitivity or a non-positive / NaN noise are left out. A parameter is not identifiable when
/// its direction lies in J's null space (blind_share >= 0.1: the parameters can trade against
/// each other without moving a target) or the noise leaves it uncertain by more than
/// sd_ln 0.5.
std::vector<ParamUncertainty> parameter_uncertainty(const std::vector<std::vector<double>>& s,
                                                    const std::vector<double>& rel_se);

} // namespace rocklab::calibration
