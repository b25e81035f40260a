// Internal to viz/: the VTK building blocks the ParaView series share (arrays, one polydata
// file, frame field data, the crack polygons). Units SI.
#pragma once

#include "io/output_dir.hpp"
#include "viz/vtk_output.hpp"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataWriter.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <numbers>
#include <vector>

namespace rocklab::vtkw {

constexpr double kPi = std::numbers::pi;

inline vtkNew<vtkDoubleArray> vector_array(const char* name, const std::vector<Vec3>& v) {
  vtkNew<vtkDoubleArray> a;
  a->SetName(name);
  a->SetNumberOfComponents(3);
  a->SetNumberOfTuples(static_cast<vtkIdType>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i)
    a->SetTuple3(static_cast<vtkIdType>(i), v[i].x(), v[i].y(), v[i].z());
  return a;
}

template <class T, class Arr> vtkNew<Arr> scalar_array(const char* name, const std::vector<T>& v) {
  vtkNew<Arr> a;
  a->SetName(name);
  a->SetNumberOfTuples(static_cast<vtkIdType>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i)
    a->SetValue(static_cast<vtkIdType>(i), v[i]);
  return a;
}

// One VTK XML file (appended raw data); a failed write is our OutputError, not VTK's log.
// `pieces` > 1 streams the data from `source` one piece at a time (the source makes each piece
// when the writer asks for it), so only one piece is in memory at once.
template <class Writer>
void write_xml(vtkDataObject* data, const std::filesystem::path& p, vtkAlgorithm* source = nullptr,
               int pieces = 1) {
  vtkObject::GlobalWarningDisplayOff();
  vtkNew<Writer> w;
  w->SetFileName(p.string().c_str());
  if (source) {
    w->SetInputConnection(source->GetOutputPort());
    w->SetNumberOfPieces(pieces);
  } else {
    w->SetInputData(data);
  }
  w->SetDataModeToAppended();
  w->EncodeAppendedDataOff();
  if (w->Write() != 1)
    throw OutputError(p.string() + ": VTK could not write the file (disk full?)");
}

inline void write_poly(vtkPolyData* pd, const std::filesystem::path& p) {
  write_xml<vtkXMLPolyDataWriter>(pd, p);
}

// Two unit vectors spanning the plane normal to n.
inline void plane_axes(const Vec3& n, Vec3& u, Vec3& v) {
  u = n.unitOrthogonal();
  v = n.cross(u);
}

// Points and cells of one polydata file (the set-up every series but the grains shares).
struct PolyBuilder {
  vtkNew<vtkPoints> pts;
  vtkNew<vtkCellArray> cells;
  vtkNew<vtkPolyData> pd;

  PolyBuilder() { pts->SetDataTypeToDouble(); }
  vtkIdType point(const Vec3& x) { return pts->InsertNextPoint(x.x(), x.y(), x.z()); }
  /// The cells are lines (2D pictures, bonds) or polygons.
  void finish(bool as_lines) {
    pd->SetPoints(pts);
    if (as_lines)
      pd->SetLines(cells);
    else
      pd->SetPolys(cells);
  }
  void write(const std::filesystem::path& path, bool as_lines) {
    finish(as_lines);
    write_poly(pd, path);
  }
  template <class T, class Arr> void cell_array(const char* name, const std::vector<T>& v) {
    pd->GetCellData()->AddArray(scalar_array<T, Arr>(name, v));
  }
  template <class T, class Arr> void point_array(const char* name, const std::vector<T>& v) {
    pd->GetPointData()->AddArray(scalar_array<T, Arr>(name, v));
  }
};

// The frame a snapshot shows, as field data of every file: step, time [s], axial strain [-] and
// axial stress [Pa] (so a frame can be labelled by strain).
inline void add_frame_fields(vtkDataObject* d, const Snapshot& s) {
  const std::pair<const char*, double> fields[] = {{"step", static_cast<double>(s.step)},
                                                   {"time", s.time},
                                                   {"axial_strain", s.axial_strain},
                                                   {"axial_stress", s.axial_stress}};
  for (const auto& [name, v] : fields) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->InsertNextValue(v);
    d->GetFieldData()->AddArray(a);
  }
}

/// One polydata file of `items` things written `per_piece` at a time: `make(first, last, b)` fills
/// builder b with items [first, last) (b.finish included), and only one piece is in memory at
/// once, made when VTK's writer asks for it (vtk_fractures.cpp). At 10k grains the power cells
/// and their polygons were 75 MB at once.
void write_poly_pieces(const std::filesystem::path& path, std::size_t items, std::size_t per_piece,
                       const std::function<void(std::size_t, std::size_t, PolyBuilder&)>& make);

/// Cracks: 3D disks (or the given polygons), 2D segments; per-contact cracks carry their damage,
/// event and energy (vtk_fractures.cpp). Written 4,096 cracks a piece.
void write_cracks(const std::vector<CrackGlyph>& cracks, const Snapshot& frame, bool per_contact,
                  const std::filesystem::path& path,
                  const std::vector<std::vector<Vec3>>* faces = nullptr);

} // namespace rocklab::vtkw
