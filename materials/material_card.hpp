// Material card: what a specimen is made of and how it is made (docs/material-format.md).
// All quantities SI. A model section's keys are read by the contact model's own reader; the
// card's bonded model reads its section itself (contact/card_bonding.hpp: its distributions,
// types and the bond it makes at each candidate), found through the registry, so a new bonded
// model is its files, its registration line and its docs, not an edit here or in genesis.
#pragma once

#include "contact/card_bonding.hpp"
#include "contact/registry.hpp"
#include "core/types.hpp"
#include "io/json_input.hpp"

#include <nlohmann/json.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace rocklab {

enum class SpecimenShape { Rectangle, Disk2D, Prism, Cylinder, Disk3D };

struct ShapeSpec {
  SpecimenShape shape = SpecimenShape::Prism;
  Vec3 size = Vec3::Zero(); ///< rectangle/prism: edge lengths; cylinder: (D, H, 0); disks: (D,
                            ///< thickness or 0, 0) [m]
  /// A disk cut with two flats normal to y (a flattened Brazilian disk): the loading angle 2a
  /// the flats subtend at the centre, each at |y| = R cos a [rad]; 0: round.
  double flat_angle = 0;
  double volume(int dim) const;
  bool contains(const Vec3& x, double margin = 0) const; ///< x relative to the shape centre
  bool within_flats(const Vec3& x, double margin) const; ///< |y| inside the flats (or no flats)
};

/// A planar joint (or a set of parallel ones) inserted as smooth joints.
struct JointSpec {
  Vec3 point = Vec3::Zero(); ///< a point on the (first) plane, relative to the specimen centre [m]
  double dip = 0, ddir = 0;  ///< [deg]
  double spacing = 0;        ///< > 0: a set of planes this far apart [m]
  SmoothJointProps props;    ///< bonded via props.bond
};

struct MaterialCard {
  std::string file, name, source, text_hash;
  nlohmann::json raw;
  int dim = 3;
  double density = 2650;       ///< grain density [kg/m^3]
  double r_min = 0, r_max = 0; ///< uniform radius range [m]
  std::vector<std::pair<double, double>>
      sieve; ///< (diameter [m], mass fraction passing), ascending
  double porosity = 0.36;
  ShapeSpec vessel;                                 ///< the packed block
  std::string vessel_file, vessel_key = "specimen"; ///< where it was given ("": the card's file)
  std::optional<ShapeSpec> cut;                     ///< test shape cut from the block
  std::uint64_t seed = 1;
  // packing
  enum class Packing { Contraction, Scaling } packing_method = Packing::Contraction;
  double packing_friction = 0.5;     ///< initial grain friction of the compaction [-]
  double porosity_tolerance = 0.003; ///< allowed |porosity - target| [-]
  double compaction_strain = 5e-4;   ///< p / E* of the soft springs used for compaction [-]
  double cloud_porosity = 0.5;
  double max_overlap_ratio = 0.25;
  /// `packing.margin_ratio`: detection margin / R_avg while packing; <= 0 (default): the old rule
  /// max(0.05 R_avg, g_i), which ties the packing to the installation gap.
  double packing_margin_ratio = 0;
  double equilibrium_ratio = 5e-3; ///< mean unbalanced-force ratio for "at rest"
  std::int64_t max_cycles = 2'000'000;
  // installation
  double pressure = 1e5; ///< material-genesis (installation) pressure [Pa]
  double pressure_tolerance = 0.02;
  double install_gap = 0; ///< g_i [m]
  /// `installation.draws`: "per_contact" draws each bonded contact's type and strengths from its
  /// own key (common random numbers: a small parameter step changes few contacts, which a
  /// calibration needs); "sequence" (default) from one stream in shuffled contact order.
  bool per_contact_draws = false;
  /// `installation.stiffness_ramp`: steps over which the card's stiffness replaces the soft
  /// packing springs (geometric), the vessel servo holding the pressure; 0: at once.
  std::int64_t stiffness_ramp = 0;
  // contacts
  LinearProps linear; ///< grain-wall, non-bonded and new contacts
  /// The card's bonded model (its section: "flatjoint", "parallelbond", ...); null: none, every
  /// contact linear.
  std::shared_ptr<const CardBonding> bonding;
  // release
  double residual_tolerance = 0.05; ///< mean residual stress / pressure after release
  bool eliminate_floaters = false;
  /// `packing.import`: the grains come from this text file (resolved path; "x y z r" or in 2D
  /// "x y r" per line) instead of being packed in a vessel; empty: packed.
  std::string packing_import;
  double install_gap_ratio = -1; ///< `installation.gap_ratio` when given (else -1)
  /// > 1: before bonding, touching grains are joined into rigid clumps of up to this many
  /// pebbles (rock-impact thesis Appendix B); 0: single grains.
  int clump_max = 0;
  std::vector<JointSpec> joints;
};

/// A shape as JSON in the card's own form ({"shape": "cylinder", "diameter": .., "height": ..}).
nlohmann::json shape_json(const ShapeSpec& s, int dim);
/// Read a shape written by shape_json (or a card's `specimen`; `cut`: a card's `cut`, where a
/// disk may have flats); errors name file and key.
ShapeSpec shape_from_json(const nlohmann::json& j, int dim, const std::string& file,
                          const std::string& key, bool cut = false);

/// Read and validate a material card; errors name the file, key, value and allowed range.
MaterialCard load_material_card(const std::string& path);

/// A JSON value given somewhere else than the card, with where it was given (for errors).
struct JsonAt {
  nlohmann::json value; ///< null: not given
  std::string file, key;
};

/// What a command line (`rocklab genesis --shape/--cut/--seed`) or a protocol's specimen changes
/// of a card before genesis.
struct GenesisOverrides {
  JsonAt shape;                      ///< replaces the specimen shape (the card's form)
  JsonAt cut;                        ///< replaces the cut (a test shape cut from the block)
  std::optional<std::uint64_t> seed; ///< replaces the random seed
};

/// Apply the overrides to a card; a bad shape fails naming where it was given.
void apply_overrides(MaterialCard& card, const GenesisOverrides& o);

} // namespace rocklab
