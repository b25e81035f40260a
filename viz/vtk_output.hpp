// ParaView output with VTK's own XML writers: grains (.vtu points), bonded contacts (.vtp lines),
// cracks (.vtp: disks in 3D, segments in 2D), walls (.vtp), and one .pvd collection per series.
// All coordinates and fields SI.
#pragma once

#include <cmath>

#include "core/model.hpp"
#include "viz/power_cells.hpp"

#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace rocklab {

/// A crack as drawn: a disk of diameter `size` (3D) or a segment of length `size` (2D).
struct CrackGlyph {
  Vec3 position = Vec3::Zero(); ///< [m]
  Vec3 normal = Vec3::UnitZ();
  double size = 0; ///< [m]
  int mode = 1;    ///< 1 tension, 2 shear
  double time = 0; ///< [s]
  std::int64_t step = 0;
  // one crack per contact only:
  double damage = 1; ///< broken parts / parts of the bond
  int event = -1;    ///< fracture event of its first break
  double energy = 0; ///< released [J]
};

/// A fracture event as drawn: a point at the centroid of its cracks.
struct EventGlyph {
  int id = 0;
  Vec3 position = Vec3::Zero();  ///< [m]
  double time = 0, duration = 0; ///< [s]
  int cracks = 0, contacts = 0;
  double energy = 0;             ///< [J]
  double magnitude = 0;          ///< energy magnitude
  double moment_magnitude = NAN; ///< Mw of its moment tensor (NaN: none followed)
  int source_type = -1;          ///< 0 tensile, 1 shear, 2 implosive (Feignier & Young), -1 none
  double r = NAN;                ///< Feignier & Young's R [-]
};

/// What one snapshot shows: copied out of the model, so it can be written later.
struct Snapshot {
  int dim = 3;
  double time = 0; ///< model time [s]
  std::int64_t step = 0;
  double axial_strain = 0;
  double axial_stress = 0; ///< [Pa], compression positive
  // grains
  std::vector<Vec3> pos, vel, disp; ///< [m], [m/s], displacement since the test began [m]
  std::vector<double> radius;       ///< [m]
  std::vector<std::int32_t> group;
  std::vector<std::int64_t> id;
  /// rotation since the loading began (only when the test tracks orientation, else empty) as a
  /// rotation vector, axis * angle [rad]
  std::vector<Vec3> rotation;
  /// Average stress of each grain from its contact forces [Pa], compression positive (see
  /// grain_stress); 2D: the in-plane components, zz = 0
  std::vector<Eigen::Matrix3d> stress;
  std::vector<double> bond_damage; ///< broken parts / parts of the grain's bonds (0 if none)
  // bonded contacts: every contact whose model has a bond (BondView), and smooth joints
  std::vector<std::array<Vec3, 2>> bond_ends; ///< the two grain centres [m]
  /// the contact model's index in the registry (1 linearpbond, 2 flatjoint, 3 smoothjoint,
  /// 4 hysteretic, 6 contactbond)
  std::vector<std::int32_t> bond_model;
  std::vector<std::int32_t> bond_state; ///< 0 no bonded part left, 1 partly, 2 intact
  std::vector<double> broken_fraction;  ///< broken parts / parts (flat joints: elements)
  /// the contact's force and moment on grain 2 in contact-plane terms: normal force (tension
  /// positive) [N], shear force magnitude [N], twisting and bending moment magnitudes [N m]
  std::vector<double> normal_force, shear_force, twisting_moment, bending_moment;
  // walls (platens, confinement)
  std::vector<Wall> walls;
  double wall_extent = 1; ///< drawn length of unbounded cylinder walls [m]
  // cracks so far
  std::vector<CrackGlyph> cracks;
  /// one crack per broken contact and the fracture events (filled once the test is over)
  std::vector<CrackGlyph> contact_cracks;
  std::vector<std::array<std::int64_t, 2>> contact_crack_grains; ///< ids of each one's grains
  std::vector<EventGlyph> events;
  /// the specimen's outline the grains' power cells are clipped to (dim 0: unknown, then the
  /// smallest box or cylinder holding the grains); kept in the grains file's field data
  ClipShape outline{0};
};

/// What the power cells of the last fracture frame measured.
struct CellSummary {
  std::size_t grains = 0, hidden = 0; ///< grains, and those without a cell
  double volume_sum = 0;              ///< of the clipped cells [m^3] (2D: m^2 x unit thickness)
  double shape_volume = 0;            ///< of the shape they are clipped to
  std::size_t faced_cracks = 0;       ///< contact cracks drawn as their grains' shared face
  std::size_t contact_cracks = 0;
};

/// The average stress in each grain from its contact forces (Love-Weber): sigma_p = -(1 - n) /
/// V_p * sum_c sym((x_c - x_p) f_c), f_c the force on the grain at contact c, V_p its volume (2D:
/// area x unit thickness) and 1 - n = sum V_p / `specimen_volume` the solid fraction, so the
/// volume-weighted mean over the grains is the specimen's average stress (1/V) sum x f, which
/// equals the platen stress in equilibrium. Compression positive [Pa]. `specimen_volume` <= 0:
/// the solid stress (n = 0).
std::vector<Eigen::Matrix3d> grain_stress(const Model& m, double specimen_volume);

/// Copy a snapshot out of the model; `reference` holds the grain positions the displacement is
/// measured from (same order as the balls; empty: zero displacement); `specimen_volume` [m^3]
/// scales the grain stresses (grain_stress).
Snapshot take_snapshot(const Model& m, const std::vector<Vec3>& reference, double axial_strain,
                       double axial_stress = 0, double specimen_volume = 0);

/// Writes snapshots as numbered files in `dir` (grains_0000.vtu, bonds_0000.vtp, cracks_0000.vtp,
/// walls_0000.vtp) and the collections grains.pvd, bonds.pvd, cracks.pvd, walls.pvd.
class VtkSeries {
public:
  explicit VtkSeries(std::filesystem::path dir) : dir_(std::move(dir)) {}
  /// Write one snapshot; returns the names of the files written (relative to dir). With a tag
  /// (e.g. "peak") the files are grains_TAG.vtu etc., overwritten by a later snapshot of the same
  /// tag, and appear in the collections at their time.
  std::vector<std::string> write(const Snapshot& s, const std::string& tag = "");
  /// Once the test is over: for every snapshot written, the grains' power cells (cells_*.vtp,
  /// from the grains file), the per-contact cracks as the faces their grains' cells share
  /// (contact_cracks_*.vtp; a disk where the cells do not touch) and the fracture events
  /// (events_*.vtp) as of its time (`at(time)` gives a Snapshot with contact_cracks, their
  /// grains, events and round). Returns what the last frame's cells measured. Without
  /// `with_cells` no cells are made and the contact cracks are disks.
  CellSummary write_fractures(const std::function<Snapshot(double)>& at, bool with_cells = true);
  /// Grains per piece of a cells file: the cells are made and written one piece at a time, so
  /// that a large packing's cells are never all in memory (default 1024).
  void set_cell_piece_grains(std::size_t n) { cell_piece_grains_ = n; }
  /// Write the .pvd collections (time = model time); returns their names.
  std::vector<std::string> write_collections() const;
  int count() const { return static_cast<int>(times_.size()); }
  /// The (time, index) list, for checkpoints.
  const std::vector<double>& times() const { return times_; }
  void set_times(std::vector<double> t) { times_ = std::move(t); }
  /// Tagged snapshots and their times, for checkpoints.
  const std::map<std::string, double>& tagged() const { return tagged_; }
  void set_tagged(std::map<std::string, double> t) { tagged_ = std::move(t); }

private:
  std::filesystem::path dir_;
  std::vector<double> times_;
  std::map<std::string, double> tagged_;
  bool fractures_ = false, cells_ = false;
  std::size_t cell_piece_grains_ = 1024;
  /// (file index, time) of every snapshot written: the numbered ones in order, then the tagged.
  std::vector<std::pair<std::string, double>> snapshot_files() const;
};

/// Number of points, cells and the names of the point/cell arrays of a VTK XML file, read back
/// with VTK's XML readers (.vtu or .vtp). Used by the tests.
struct VtkFileInfo {
  long long points = 0, cells = 0;
  std::vector<std::string> point_arrays, cell_arrays;
  std::map<std::string, std::vector<double>> point_values; ///< one-component point arrays
  std::map<std::string, std::vector<double>> cell_values;  ///< one-component cell arrays
  std::map<std::string, std::vector<double>> point_tuples; ///< multi-component point arrays, flat
  std::map<std::string, double> field_values;              ///< first value of each field array
  std::map<std::string, std::vector<double>> field_tuples; ///< every value of each field array
  std::vector<Vec3> positions;                             ///< the points
};
VtkFileInfo read_vtk_info(const std::string& path);

} // namespace rocklab
