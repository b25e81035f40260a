#include "viz/vtk_output.hpp"

#include <algorithm>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIntArray.h>
#include <vtkLongLongArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <stdexcept>

namespace rocklab {

namespace {

constexpr double kPi = std::numbers::pi;

vtkNew<vtkDoubleArray> vector_array(const char* name, const std::vector<Vec3>& v) {
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

void write_poly(vtkPolyData* pd, const std::filesystem::path& p) {
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetFileName(p.string().c_str());
  w->SetInputData(pd);
  w->SetDataModeToAppended();
  w->EncodeAppendedDataOff();
  if (w->Write() != 1)
    throw std::runtime_error(p.string() + ": VTK could not write the file");
}

// Two unit vectors spanning the plane normal to n.
void plane_axes(const Vec3& n, Vec3& u, Vec3& v) {
  u = n.unitOrthogonal();
  v = n.cross(u);
}

} // namespace

Snapshot take_snapshot(const Model& m, const std::vector<Vec3>& reference, double axial_strain) {
  Snapshot s;
  s.dim = m.settings.dim;
  s.time = m.time();
  s.step = m.step();
  s.axial_strain = axial_strain;
  const Balls& b = m.balls;
  s.pos = b.pos;
  s.vel = b.vel;
  s.radius = b.radius;
  s.group = b.group;
  s.id = b.id;
  s.disp.resize(b.size(), Vec3::Zero());
  if (reference.size() == b.size())
    for (std::size_t i = 0; i < b.size(); ++i)
      s.disp[i] = b.pos[i] - reference[i];
  for (const Contact& c : m.contacts()) {
    if (c.kind != ContactKind::BallBall)
      continue;
    const BondView v = contact_bond_view(m.batches(), c.model, c.slot);
    if (v.parts == 0)
      continue; // no bond: never bonded, or a gapped or slit flat joint
    s.bond_ends.push_back(
        {b.pos[static_cast<std::size_t>(c.end1)], b.pos[static_cast<std::size_t>(c.end2)]});
    s.bond_model.push_back(static_cast<std::int32_t>(c.model));
    s.bond_state.push_back(v.intact == 0 ? 0 : (v.broken == 0 ? 2 : 1));
    s.broken_fraction.push_back(static_cast<double>(v.broken) / static_cast<double>(v.parts));
  }
  s.walls = m.walls;
  double lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < b.size(); ++i) {
    lo = std::min(lo, b.pos[i].minCoeff() - b.radius[i]);
    hi = std::max(hi, b.pos[i].maxCoeff() + b.radius[i]);
  }
  s.wall_extent = b.size() ? hi - lo : 1.0;
  return s;
}

std::vector<std::string> VtkSeries::write(const Snapshot& s, const std::string& tag) {
  std::filesystem::create_directories(dir_);
  char index[32];
  std::snprintf(index, sizeof index, "%04d", count());
  if (!tag.empty())
    std::snprintf(index, sizeof index, "%s", tag.c_str());
  const std::string gname = std::string("grains_") + index + ".vtu";
  const std::string bname = std::string("bonds_") + index + ".vtp";
  const std::string cname = std::string("cracks_") + index + ".vtp";
  const std::string wname = std::string("walls_") + index + ".vtp";
  const auto n = static_cast<vtkIdType>(s.pos.size());

  { // grains: one vertex cell per grain
    vtkNew<vtkPoints> pts;
    pts->SetDataTypeToDouble();
    pts->SetNumberOfPoints(n);
    for (vtkIdType i = 0; i < n; ++i) {
      const Vec3& x = s.pos[static_cast<std::size_t>(i)];
      pts->SetPoint(i, x.x(), x.y(), x.z());
    }
    vtkNew<vtkUnstructuredGrid> ug;
    ug->SetPoints(pts);
    ug->Allocate(n);
    for (vtkIdType i = 0; i < n; ++i)
      ug->InsertNextCell(VTK_VERTEX, 1, &i);
    vtkPointData* pd = ug->GetPointData();
    pd->AddArray(scalar_array<double, vtkDoubleArray>("radius", s.radius));
    pd->AddArray(vector_array("velocity", s.vel));
    pd->AddArray(vector_array("displacement", s.disp));
    pd->AddArray(scalar_array<std::int32_t, vtkIntArray>("group", s.group));
    pd->AddArray(scalar_array<std::int64_t, vtkLongLongArray>("id", s.id));
    vtkNew<vtkXMLUnstructuredGridWriter> w;
    w->SetFileName((dir_ / gname).string().c_str());
    w->SetInputData(ug);
    w->SetDataModeToAppended();
    w->EncodeAppendedDataOff();
    if (w->Write() != 1)
      throw std::runtime_error((dir_ / gname).string() + ": VTK could not write the file");
  }
  { // bonds: a line between the grain centres
    vtkNew<vtkPoints> pts;
    pts->SetDataTypeToDouble();
    vtkNew<vtkCellArray> lines;
    for (const auto& e : s.bond_ends) {
      const vtkIdType a = pts->InsertNextPoint(e[0].x(), e[0].y(), e[0].z());
      const vtkIdType b = pts->InsertNextPoint(e[1].x(), e[1].y(), e[1].z());
      const vtkIdType ids[2] = {a, b};
      lines->InsertNextCell(2, ids);
    }
    vtkNew<vtkPolyData> pd;
    pd->SetPoints(pts);
    pd->SetLines(lines);
    pd->GetCellData()->AddArray(
        scalar_array<std::int32_t, vtkIntArray>("bond_state", s.bond_state));
    pd->GetCellData()->AddArray(
        scalar_array<double, vtkDoubleArray>("broken_fraction", s.broken_fraction));
    pd->GetCellData()->AddArray(scalar_array<std::int32_t, vtkIntArray>("model", s.bond_model));
    write_poly(pd, dir_ / bname);
  }
  { // cracks: 3D disks as 16-gons, 2D segments in the xy plane
    vtkNew<vtkPoints> pts;
    pts->SetDataTypeToDouble();
    vtkNew<vtkCellArray> polys, lines;
    std::vector<std::int32_t> mode;
    std::vector<double> time, size;
    for (const CrackGlyph& c : s.cracks) {
      const double r = 0.5 * c.size;
      if (s.dim == 2) {
        const Vec3 t(-c.normal.y(), c.normal.x(), 0);
        const Vec3 a = c.position - r * t, b = c.position + r * t;
        const vtkIdType ids[2] = {pts->InsertNextPoint(a.x(), a.y(), a.z()),
                                  pts->InsertNextPoint(b.x(), b.y(), b.z())};
        lines->InsertNextCell(2, ids);
      } else {
        Vec3 u, v;
        plane_axes(c.normal, u, v);
        constexpr int kSides = 16;
        vtkIdType ids[kSides];
        for (int k = 0; k < kSides; ++k) {
          const double a = 2 * kPi * k / kSides;
          const Vec3 p = c.position + r * (std::cos(a) * u + std::sin(a) * v);
          ids[k] = pts->InsertNextPoint(p.x(), p.y(), p.z());
        }
        polys->InsertNextCell(kSides, ids);
      }
      mode.push_back(c.mode);
      time.push_back(c.time);
      size.push_back(c.size);
    }
    vtkNew<vtkPolyData> pd;
    pd->SetPoints(pts);
    if (s.dim == 2)
      pd->SetLines(lines);
    else
      pd->SetPolys(polys);
    pd->GetCellData()->AddArray(scalar_array<std::int32_t, vtkIntArray>("mode", mode));
    pd->GetCellData()->AddArray(scalar_array<double, vtkDoubleArray>("time", time));
    pd->GetCellData()->AddArray(scalar_array<double, vtkDoubleArray>("size", size));
    write_poly(pd, dir_ / cname);
  }
  { // walls: facets (segments in 2D), cylinders as 48-sided prisms or polygons
    vtkNew<vtkPoints> pts;
    pts->SetDataTypeToDouble();
    vtkNew<vtkCellArray> polys, lines;
    std::vector<std::int32_t> wall_index;
    for (std::size_t w = 0; w < s.walls.size(); ++w) {
      const Wall& wall = s.walls[w];
      if (wall.is_cylinder()) {
        constexpr int kSides = 48;
        Vec3 u, v;
        plane_axes(wall.axis, u, v);
        const double h = wall.half_height > 0 ? wall.half_height : 0.5 * s.wall_extent;
        for (int k = 0; k < kSides; ++k) {
          const double a0 = 2 * kPi * k / kSides, a1 = 2 * kPi * (k + 1) / kSides;
          const Vec3 r0 = wall.cylinder_radius * (std::cos(a0) * u + std::sin(a0) * v);
          const Vec3 r1 = wall.cylinder_radius * (std::cos(a1) * u + std::sin(a1) * v);
          if (s.dim == 2) {
            const Vec3 p0 = wall.center + r0, p1 = wall.center + r1;
            const vtkIdType ids[2] = {pts->InsertNextPoint(p0.x(), p0.y(), 0),
                                      pts->InsertNextPoint(p1.x(), p1.y(), 0)};
            lines->InsertNextCell(2, ids);
          } else {
            const Vec3 lo = wall.center - h * wall.axis, hi = wall.center + h * wall.axis;
            const Vec3 q[4] = {lo + r0, lo + r1, hi + r1, hi + r0};
            vtkIdType ids[4];
            for (int i = 0; i < 4; ++i)
              ids[i] = pts->InsertNextPoint(q[i].x(), q[i].y(), q[i].z());
            polys->InsertNextCell(4, ids);
          }
          wall_index.push_back(static_cast<std::int32_t>(w));
        }
        continue;
      }
      for (const Facet& f : wall.facets) {
        vtkIdType ids[3];
        for (int k = 0; k < f.nv; ++k)
          ids[k] = pts->InsertNextPoint(f.v[k].x(), f.v[k].y(), f.v[k].z());
        if (f.nv == 2)
          lines->InsertNextCell(2, ids);
        else
          polys->InsertNextCell(3, ids);
        wall_index.push_back(static_cast<std::int32_t>(w));
      }
    }
    vtkNew<vtkPolyData> pd;
    pd->SetPoints(pts);
    if (s.dim == 2)
      pd->SetLines(lines);
    else
      pd->SetPolys(polys);
    pd->GetCellData()->AddArray(scalar_array<std::int32_t, vtkIntArray>("wall", wall_index));
    write_poly(pd, dir_ / wname);
  }
  if (tag.empty())
    times_.push_back(s.time);
  else
    tagged_[tag] = s.time;
  return {gname, bname, cname, wname};
}

std::vector<std::string> VtkSeries::write_collections() const {
  std::vector<std::string> out;
  for (const char* series : {"grains", "bonds", "cracks", "walls"}) {
    const char* ext = std::string(series) == "grains" ? "vtu" : "vtp";
    std::string text = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
                       "byte_order=\"LittleEndian\">\n  <Collection>\n";
    // Numbered and tagged snapshots in time order (a tag goes before a numbered file of the
    // same time).
    std::vector<std::pair<double, std::string>> entries;
    for (std::size_t i = 0; i < times_.size(); ++i) {
      char index[32];
      std::snprintf(index, sizeof index, "%04zu", i);
      entries.emplace_back(times_[i], index);
    }
    for (const auto& [tag, t] : tagged_)
      entries.emplace_back(t, tag);
    std::stable_sort(entries.begin(), entries.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [t, index] : entries) {
      char line[256];
      std::snprintf(line, sizeof line,
                    "    <DataSet timestep=\"%.17g\" group=\"\" part=\"0\" file=\"%s_%s.%s\"/>\n",
                    t, series, index.c_str(), ext);
      text += line;
    }
    text += "  </Collection>\n</VTKFile>\n";
    const std::string name = std::string(series) + ".pvd";
    std::ofstream f(dir_ / name, std::ios::binary);
    f << text;
    if (!f)
      throw std::runtime_error((dir_ / name).string() + ": cannot write");
    out.push_back(name);
  }
  return out;
}

VtkFileInfo read_vtk_info(const std::string& path) {
  VtkFileInfo info;
  vtkDataSet* ds = nullptr;
  vtkNew<vtkXMLUnstructuredGridReader> ur;
  vtkNew<vtkXMLPolyDataReader> pr;
  if (path.size() > 4 && path.substr(path.size() - 4) == ".vtu") {
    if (!ur->CanReadFile(path.c_str()))
      throw std::runtime_error(path + ": not a VTK XML unstructured grid");
    ur->SetFileName(path.c_str());
    ur->Update();
    ds = ur->GetOutput();
  } else {
    if (!pr->CanReadFile(path.c_str()))
      throw std::runtime_error(path + ": not a VTK XML polydata file");
    pr->SetFileName(path.c_str());
    pr->Update();
    ds = pr->GetOutput();
  }
  info.points = ds->GetNumberOfPoints();
  info.cells = ds->GetNumberOfCells();
  for (int i = 0; i < ds->GetPointData()->GetNumberOfArrays(); ++i)
    info.point_arrays.emplace_back(ds->GetPointData()->GetArrayName(i));
  for (int i = 0; i < ds->GetCellData()->GetNumberOfArrays(); ++i) {
    vtkDataArray* a = ds->GetCellData()->GetArray(i);
    info.cell_arrays.emplace_back(ds->GetCellData()->GetArrayName(i));
    if (a && a->GetNumberOfComponents() == 1)
      for (vtkIdType k = 0; k < a->GetNumberOfTuples(); ++k)
        info.cell_values[info.cell_arrays.back()].push_back(a->GetTuple1(k));
  }
  return info;
}

} // namespace rocklab
