// ParaView output with VTK's own XML writers: grains (.vtu points), bonded contacts (.vtp lines),
// cracks (.vtp: disks in 3D, segments in 2D), walls (.vtp), and one .pvd collection per series.
// All coordinates and fields SI.
#pragma once

#include "core/model.hpp"

#include <array>
#include <filesystem>
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
};

/// What one snapshot shows: copied out of the model, so it can be written later.
struct Snapshot {
  int dim = 3;
  double time = 0; ///< model time [s]
  std::int64_t step = 0;
  double axial_strain = 0;
  // grains
  std::vector<Vec3> pos, vel, disp; ///< [m], [m/s], displacement since the test began [m]
  std::vector<double> radius;       ///< [m]
  std::vector<std::int32_t> group;
  std::vector<std::int64_t> id;
  /// rotation since the loading began (only when the test tracks orientation, else empty) as a
  /// rotation vector, axis * angle [rad]
  std::vector<Vec3> rotation;
  // bonded contacts: every contact whose model has a bond (BondView), and smooth joints
  std::vector<std::array<Vec3, 2>> bond_ends; ///< the two grain centres [m]
  /// the contact model's index in the registry (1 linearpbond, 2 flatjoint, 3 smoothjoint,
  /// 4 hysteretic, 6 contactbond)
  std::vector<std::int32_t> bond_model;
  std::vector<std::int32_t> bond_state; ///< 0 no bonded part left, 1 partly, 2 intact
  std::vector<double> broken_fraction;  ///< broken parts / parts (flat joints: elements)
  // walls (platens, confinement)
  std::vector<Wall> walls;
  double wall_extent = 1; ///< drawn length of unbounded cylinder walls [m]
  // cracks so far
  std::vector<CrackGlyph> cracks;
};

/// Copy a snapshot out of the model; `reference` holds the grain positions the displacement is
/// measured from (same order as the balls; empty: zero displacement).
Snapshot take_snapshot(const Model& m, const std::vector<Vec3>& reference, double axial_strain);

/// Writes snapshots as numbered files in `dir` (grains_0000.vtu, bonds_0000.vtp, cracks_0000.vtp,
/// walls_0000.vtp) and the collections grains.pvd, bonds.pvd, cracks.pvd, walls.pvd.
class VtkSeries {
public:
  explicit VtkSeries(std::filesystem::path dir) : dir_(std::move(dir)) {}
  /// Write one snapshot; returns the names of the files written (relative to dir). With a tag
  /// (e.g. "peak") the files are grains_TAG.vtu etc., overwritten by a later snapshot of the same
  /// tag, and appear in the collections at their time.
  std::vector<std::string> write(const Snapshot& s, const std::string& tag = "");
  /// Write the four .pvd collections (time = model time); returns their names.
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
};

/// Number of points, cells and the names of the point/cell arrays of a VTK XML file, read back
/// with VTK's XML readers (.vtu or .vtp). Used by the tests.
struct VtkFileInfo {
  long long points = 0, cells = 0;
  std::vector<std::string> point_arrays, cell_arrays;
  std::map<std::string, std::vector<double>> point_values; ///< one-component point arrays
  std::map<std::string, std::vector<double>> cell_values;  ///< one-component cell arrays
};
VtkFileInfo read_vtk_info(const std::string& path);

} // namespace rocklab
