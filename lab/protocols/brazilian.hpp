// The Brazilian test's measurement rules, exposed for tests: when the disk split and which load
// is its tensile strength (lab/protocols/brazilian.cpp). Units SI.
#pragma once

#include "lab/crack_monitor.hpp"
#include "lab/frame/loading_frame.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace rocklab {

/// The centre's tensile stress per 2F/(pi D t) when the load is spread uniformly over two arcs
/// that subtend `loading_angle` = 2a at the centre: (sin 2a - a) / a (Hondros 1959; 1 for a line
/// load, 0.960 at 2a = 20 deg, 0.910 at 30 deg); a flattened disk's flats load it so.
double flat_disk_factor(double loading_angle);

/// Cracks within 0.2 D of the loaded diameter (the y axis through the centre), binned by their
/// position along it in ten tenths: the split is complete once one run of cracked tenths spans
/// `fraction` of them, bridging at most one single empty tenth (a fracture through a contact with
/// no bond to break, slit or unbonded, leaves no crack record there; scattered cracks in every
/// other tenth are diffuse damage, not a split: bridging them all declared one at 7 MPa in a 2D
/// disk that failed at 27). Crushing under both platens covers the two ends of the diameter, not
/// the middle, and does not join up.
class SplitBins {
public:
  SplitBins(const SpecimenGeometry& g, double fraction);
  /// Bins one crack; true once the run is long enough.
  bool add(const Crack& c);

private:
  double d_;
  Vec3 centre_;
  int need_;
  std::array<bool, 10> bins_{};
};

/// The step of the crack that completed the diametral split (cracks within 0.2 D of the loaded
/// diameter spanning `fraction` of its ten bins in one run that bridges at most one empty bin),
/// or -1 without a split.
std::int64_t split_crack_step(const std::vector<Crack>& cracks, const SpecimenGeometry& g,
                              double fraction);

/// The tension the disk carries across its loaded diameter: the tensile x-components of the
/// grain-grain contact forces that cross a plane normal to x, averaged over five planes at the
/// centre and 0.05 D and 0.1 D either side of it (a fracture wanders) [N]; 2D per unit thickness.
/// An elastic disk under line loads carries 2F/pi across its diameter (Hondros; Jaeger & Cook).
double diametral_tension(const Model& m, const SpecimenGeometry& g);

/// How the platens spread their load over the disk's rim (lab/protocols/brazilian_arc.cpp). Each
/// platen's contacts are weighted by their force along the loading axis; the arc is that of a
/// uniform load with the same force-weighted spread across the loading axis: half-width a =
/// sqrt(3) x the force-weighted standard deviation of the contacts' offsets from their centroid
/// (exact for a uniform pressure over [-a, a], 0 for one contact), half-angle asin(a / R).
struct LoadedArc {
  double half_angle = 0; ///< the mean of the two platens' half-angles [rad]
  int contacts = 0;      ///< platen contacts carrying load (both platens)
};
LoadedArc loaded_arc(const Model& m, const SpecimenGeometry& g);
/// One platen's contacts as loaded_arc sums them: offsets x across the loading axis [m] weighted
/// by their force f [N].
struct ArcSums {
  double w = 0, x = 0, xx = 0;
  int n = 0;
  void add(double offset, double force) {
    w += force, x += force * offset, xx += force * offset * offset, n += 1;
  }
  /// The half-width of the uniform load with the same force-weighted spread [m] (0: none).
  double half_width() const;
};

/// One reading of the tension across the diameter per unit platen force [-] (elastic disk under
/// line loads: 2/pi on one plane) with the load [Pa] and the loaded arc at the same step.
struct TensionReading {
  std::int64_t step = 0;
  double load = 0, ratio = 0;
  double arc = 0;          ///< LoadedArc::half_angle [rad]
  int contacts = 0;        ///< LoadedArc::contacts
  std::int64_t cracks = 0; ///< cracks so far
  double strain = 0;       ///< platen travel / D [-]
};

/// When the disk lost its diametral tension: the first reading of a run of readings whose ratio
/// stayed below `kept` times the reference for at least `persist` steps (or to the end), the
/// reference being the largest ratio of the earlier readings that carried at least 0.9 of the
/// peak so far (the climb; a falling load leaves the internal tension behind for a while).
/// Readings below the load `floor` [Pa] or below `failed` of the peak so far (a collapse is the
/// re-seating rule's, not a split) are skipped. step -1 if it never did.
struct TensionLoss {
  std::int64_t step = -1;
  double reference = 0, ratio = 0; ///< the reference ratio and the ratio at the loss [-]
};
TensionLoss tension_loss(const std::vector<TensionReading>& r, double kept, double failed,
                         double floor, std::int64_t persist);

/// tension_loss one reading at a time (the test's stop rule reads it while loading).
class TensionWatch {
public:
  TensionWatch(double kept, double failed, double floor, std::int64_t persist)
      : kept_(kept), failed_(failed), floor_(floor), persist_(persist) {}
  void add(const TensionReading& x);
  /// A loss that lasted `persist` steps (step -1: none yet).
  const TensionLoss& lost() const { return lost_; }
  /// As tension_loss: a lasting loss, else one still running, else the reference alone.
  TensionLoss result() const;

private:
  double kept_, failed_, floor_;
  std::int64_t persist_;
  double peak_ = 0, ref_ = 0;
  TensionLoss low_, lost_;
};

/// The reading with the largest load up to step `split` (the peak itself when it came first);
/// load -1 when no reading precedes the split.
LabSample strongest_before(const std::vector<LabSample>& samples, const PeakRecord& peak,
                           std::int64_t split);

/// Where a disk's fracture started (lab/protocols/brazilian_validity.cpp), read from the cracks
/// within 0.2 D of the loaded diameter up to the step of its tensile strength. A laboratory keeps
/// a disk whose splitting fracture starts in the centre region and discards one that fails from a
/// loading point (ISRM 1978).
struct SplitOrigin {
  /// "centre": its first cracks lie in the middle third of the diameter; "diameter": between
  /// that and the outer thirds, or scattered along it; "platen": they lie within D/6 of a platen,
  /// or most of the damage does (crushing at the loading points), more than a scatter along the
  /// diameter puts there by chance; "none": no crack in the band.
  std::string site = "none";
  double start = std::nan(""); ///< median |y| / (D/2) of the band's first quarter of cracks (>= 3)
  double platen_share = std::nan(""); ///< the band's cracks within D/6 of a platen (uniform: 1/3)
  int cracks = 0;                     ///< the band's cracks up to the step
  int first = 0;                      ///< the first quarter's cracks (at least 3)
  int first_at_platen = 0;            ///< of those, within D/6 of a platen
  /// The chance that cracks scattered evenly along the diameter put at least as many of the first
  /// quarter (start) or of all (share) within D/6 of a platen: the one-sided binomial tail.
  double start_chance = std::nan(""), share_chance = std::nan("");
  bool valid = false; ///< the fracture did not start at a platen
};
/// A disk whose damage lies mostly at the platens failed there whatever its first cracks did.
inline constexpr double kPlatenShareInvalid = 0.5;
/// A platen start must be more than chance: at most this probability under an even scatter.
inline constexpr double kPlatenChance = 0.05;
/// P(X >= k) for X ~ Binomial(n, p).
double binomial_upper_tail(int k, int n, double p);
SplitOrigin split_origin(const std::vector<Crack>& cracks, const SpecimenGeometry& g,
                         std::int64_t until);

} // namespace rocklab
