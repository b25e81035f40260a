#include "viz/vtk_output.hpp"

#include "io/output_dir.hpp"
#include "viz/vtk_write.hpp"

#include <algorithm>

#include <Eigen/Eigenvalues>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
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

using namespace vtkw;

std::vector<Eigen::Matrix3d> grain_stress(const Model& m, double specimen_volume) {
  const Balls& b = m.balls;
  std::vector<Eigen::Matrix3d> sum(b.size(), Eigen::Matrix3d::Zero());
  const auto& cs = m.contacts();
  const auto& out = m.contact_outputs();
  for (std::size_t k = 0; k < cs.size() && k < out.size(); ++k) {
    const Contact& c = cs[k];
    const Vec3& f2 = out[k].force; // on piece 2; piece 1 gets -f2
    const auto i = static_cast<std::size_t>(c.end1);
    sum[i] -= (out[k].xc - b.pos[i]) * f2.transpose();
    if (c.kind == ContactKind::BallBall) {
      const auto j = static_cast<std::size_t>(c.end2);
      sum[j] += (out[k].xc - b.pos[j]) * f2.transpose();
    }
  }
  double solid = 0;
  std::vector<double> vol(b.size());
  for (std::size_t i = 0; i < b.size(); ++i) {
    const double r = b.radius[i];
    vol[i] = m.settings.dim == 2 ? kPi * r * r : 4.0 / 3.0 * kPi * r * r * r;
    solid += vol[i];
  }
  const double fraction = specimen_volume > 0 ? solid / specimen_volume : 1.0;
  for (std::size_t i = 0; i < b.size(); ++i) // compression positive: minus the tension-positive
    sum[i] = -fraction / vol[i] * 0.5 * (sum[i] + sum[i].transpose());
  return sum;
}

Snapshot take_snapshot(const Model& m, const std::vector<Vec3>& reference, double axial_strain,
                       double axial_stress, double specimen_volume) {
  Snapshot s;
  s.dim = m.settings.dim;
  s.time = m.time();
  s.step = m.step();
  s.axial_strain = axial_strain;
  s.axial_stress = axial_stress;
  s.stress = grain_stress(m, specimen_volume);
  std::vector<int> parts(m.balls.size(), 0), broken(m.balls.size(), 0);
  const Balls& b = m.balls;
  s.pos = b.pos;
  s.vel = b.vel;
  s.radius = b.radius;
  s.group = b.group;
  s.id = b.id;
  if (b.tracks_orientation())
    for (const Eigen::Quaterniond& q : b.orient)
      s.rotation.push_back(rotation_vector(q));
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
    const auto k = static_cast<std::size_t>(&c - m.contacts().data());
    const ContactResult f = local_components(c, m.contact_outputs()[k]);
    s.normal_force.push_back(f.Fn);
    s.shear_force.push_back(std::hypot(f.Fss, f.Fst));
    s.twisting_moment.push_back(std::abs(f.Mt));
    s.bending_moment.push_back(std::hypot(f.Mbs, f.Mbt));
    for (const auto e : {c.end1, c.end2}) {
      parts[static_cast<std::size_t>(e)] += v.parts;
      broken[static_cast<std::size_t>(e)] += v.broken;
    }
  }
  for (std::size_t i = 0; i < b.size(); ++i)
    s.bond_damage.push_back(parts[i] > 0 ? static_cast<double>(broken[i]) / parts[i] : 0.0);
  s.walls = m.walls;
  double lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < b.size(); ++i) {
    lo = std::min(lo, b.pos[i].minCoeff() - b.radius[i]);
    hi = std::max(hi, b.pos[i].maxCoeff() + b.radius[i]);
  }
  s.wall_extent = b.size() ? hi - lo : 1.0;
  return s;
}

namespace {

// A grain's stress tensor (9 components), its principal stresses (sigma1 >= sigma2 >= sigma3),
// mean stress and von Mises stress [Pa], compression positive.
void add_stress_arrays(vtkPointData* pd, const std::vector<Eigen::Matrix3d>& st) {
  vtkNew<vtkDoubleArray> t, p;
  t->SetName("stress");
  t->SetNumberOfComponents(9);
  p->SetName("principal_stress");
  p->SetNumberOfComponents(3);
  std::vector<double> mean, mises;
  for (const Eigen::Matrix3d& m : st) {
    t->InsertNextTuple(m.data());
    const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m).eigenvalues();
    p->InsertNextTuple3(ev[2], ev[1], ev[0]);
    mean.push_back(m.trace() / 3);
    mises.push_back(
        std::sqrt(0.5 * ((ev[0] - ev[1]) * (ev[0] - ev[1]) + (ev[1] - ev[2]) * (ev[1] - ev[2]) +
                         (ev[2] - ev[0]) * (ev[2] - ev[0]))));
  }
  pd->AddArray(t);
  pd->AddArray(p);
  pd->AddArray(scalar_array<double, vtkDoubleArray>("mean_stress", mean));
  pd->AddArray(scalar_array<double, vtkDoubleArray>("von_mises_stress", mises));
}

// Grains: one vertex cell per grain.
void write_grains(const Snapshot& s, const std::filesystem::path& path) {
  const auto n = static_cast<vtkIdType>(s.pos.size());
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
  if (!s.rotation.empty()) { // 2D: the signed angle about z; 3D: the angle about the axis
    std::vector<double> angle;
    for (const Vec3& r : s.rotation)
      angle.push_back(s.dim == 2 ? r.z() : r.norm());
    pd->AddArray(scalar_array<double, vtkDoubleArray>("rotation", angle));
    if (s.dim == 3)
      pd->AddArray(vector_array("rotation_vector", s.rotation));
  }
  if (!s.stress.empty())
    add_stress_arrays(pd, s.stress);
  if (!s.bond_damage.empty())
    pd->AddArray(scalar_array<double, vtkDoubleArray>("bond_damage", s.bond_damage));
  add_frame_fields(ug, s);
  if (s.outline.dim > 0) { // the outline the cells are clipped to (vtk_fractures.cpp)
    const ClipShape& c = s.outline;
    vtkNew<vtkDoubleArray> a;
    a->SetName("outline");
    for (double v : {static_cast<double>(c.round), c.lo.x(), c.lo.y(), c.lo.z(), c.hi.x(), c.hi.y(),
                     c.hi.z(), c.center.x(), c.center.y(), c.radius})
      a->InsertNextValue(v);
    ug->GetFieldData()->AddArray(a);
  }
  write_xml<vtkXMLUnstructuredGridWriter>(ug, path);
}

// Bonds: a line between the grain centres.
void write_bonds(const Snapshot& s, const std::filesystem::path& path) {
  PolyBuilder b;
  for (const auto& e : s.bond_ends) {
    const vtkIdType ids[2] = {b.point(e[0]), b.point(e[1])};
    b.cells->InsertNextCell(2, ids);
  }
  b.cell_array<std::int32_t, vtkIntArray>("bond_state", s.bond_state);
  b.cell_array<double, vtkDoubleArray>("broken_fraction", s.broken_fraction);
  b.cell_array<std::int32_t, vtkIntArray>("model", s.bond_model);
  b.cell_array<double, vtkDoubleArray>("normal_force", s.normal_force);
  b.cell_array<double, vtkDoubleArray>("shear_force", s.shear_force);
  b.cell_array<double, vtkDoubleArray>("twisting_moment", s.twisting_moment);
  b.cell_array<double, vtkDoubleArray>("bending_moment", s.bending_moment);
  add_frame_fields(b.pd, s);
  b.write(path, true);
}

// A cylinder wall as a 48-sided prism (2D: a polygon of segments).
void add_cylinder(PolyBuilder& b, const Wall& wall, int dim, double extent) {
  constexpr int kSides = 48;
  Vec3 u, v;
  plane_axes(wall.axis, u, v);
  const double h = wall.half_height > 0 ? wall.half_height : 0.5 * extent;
  for (int k = 0; k < kSides; ++k) {
    const double a0 = 2 * kPi * k / kSides, a1 = 2 * kPi * (k + 1) / kSides;
    const Vec3 r0 = wall.cylinder_radius * (std::cos(a0) * u + std::sin(a0) * v);
    const Vec3 r1 = wall.cylinder_radius * (std::cos(a1) * u + std::sin(a1) * v);
    if (dim == 2) {
      const Vec3 p0 = wall.center + r0, p1 = wall.center + r1;
      const vtkIdType ids[2] = {b.point(Vec3(p0.x(), p0.y(), 0)), b.point(Vec3(p1.x(), p1.y(), 0))};
      b.cells->InsertNextCell(2, ids);
    } else {
      const Vec3 lo = wall.center - h * wall.axis, hi = wall.center + h * wall.axis;
      const Vec3 q[4] = {lo + r0, lo + r1, hi + r1, hi + r0};
      vtkIdType ids[4];
      for (int i = 0; i < 4; ++i)
        ids[i] = b.point(q[i]);
      b.cells->InsertNextCell(4, ids);
    }
  }
}

// Walls: facets (segments in 2D), cylinders as prisms or polygons.
void write_walls(const Snapshot& s, const std::filesystem::path& path) {
  PolyBuilder b;
  std::vector<std::int32_t> wall_index;
  for (std::size_t w = 0; w < s.walls.size(); ++w) {
    const Wall& wall = s.walls[w];
    if (wall.is_cylinder()) {
      add_cylinder(b, wall, s.dim, s.wall_extent);
      wall_index.insert(wall_index.end(), 48, static_cast<std::int32_t>(w));
      continue;
    }
    for (const Facet& f : wall.facets) {
      vtkIdType ids[3];
      for (int k = 0; k < f.nv; ++k)
        ids[k] = b.point(f.v[k]);
      b.cells->InsertNextCell(f.nv, ids);
      wall_index.push_back(static_cast<std::int32_t>(w));
    }
  }
  b.cell_array<std::int32_t, vtkIntArray>("wall", wall_index);
  add_frame_fields(b.pd, s);
  b.write(path, s.dim == 2);
}

} // namespace

std::vector<std::string> VtkSeries::write(const Snapshot& s, const std::string& tag) {
  std::filesystem::create_directories(dir_);
  char index[32];
  std::snprintf(index, sizeof index, "%04d", count());
  if (!tag.empty())
    std::snprintf(index, sizeof index, "%s", tag.c_str());
  const std::vector<std::string> names = {
      std::string("grains_") + index + ".vtu", std::string("bonds_") + index + ".vtp",
      std::string("cracks_") + index + ".vtp", std::string("walls_") + index + ".vtp"};
  write_grains(s, dir_ / names[0]);
  write_bonds(s, dir_ / names[1]);
  write_cracks(s.cracks, s, false, dir_ / names[2]);
  write_walls(s, dir_ / names[3]);
  if (tag.empty())
    times_.push_back(s.time);
  else
    tagged_[tag] = s.time;
  return names;
}

std::vector<std::pair<std::string, double>> VtkSeries::snapshot_files() const {
  std::vector<std::pair<std::string, double>> files;
  for (std::size_t i = 0; i < times_.size(); ++i) {
    char index[32];
    std::snprintf(index, sizeof index, "%04zu", i);
    files.emplace_back(index, times_[i]);
  }
  for (const auto& [tag, t] : tagged_)
    files.emplace_back(tag, t);
  return files;
}

std::vector<std::string> VtkSeries::write_collections() const {
  std::vector<std::string> out;
  std::vector<const char*> all = {"grains", "bonds", "cracks", "walls"};
  if (fractures_ && cells_)
    all.push_back("cells");
  if (fractures_)
    all.insert(all.end(), {"contact_cracks", "events"});
  for (const char* series : all) {
    const char* ext = std::string(series) == "grains" ? "vtu" : "vtp";
    std::string text = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
                       "byte_order=\"LittleEndian\">\n  <Collection>\n";
    // Numbered and tagged snapshots in time order (a tag goes before a numbered file of the
    // same time).
    std::vector<std::pair<double, std::string>> entries;
    for (const auto& [index, t] : snapshot_files())
      entries.emplace_back(t, index);
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
      throw OutputError((dir_ / name).string() + ": cannot write");
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
  for (vtkIdType i = 0; i < ds->GetNumberOfPoints(); ++i) {
    double x[3];
    ds->GetPoint(i, x);
    info.positions.emplace_back(x[0], x[1], x[2]);
  }
  info.cells = ds->GetNumberOfCells();
  const auto arrays = [](vtkFieldData* data, std::vector<std::string>& names,
                         std::map<std::string, std::vector<double>>& values) {
    for (int i = 0; i < data->GetNumberOfArrays(); ++i) {
      vtkDataArray* a = data->GetArray(i);
      names.emplace_back(data->GetArrayName(i));
      if (a && a->GetNumberOfComponents() == 1)
        for (vtkIdType k = 0; k < a->GetNumberOfTuples(); ++k)
          values[names.back()].push_back(a->GetTuple1(k));
    }
  };
  arrays(ds->GetPointData(), info.point_arrays, info.point_values);
  arrays(ds->GetCellData(), info.cell_arrays, info.cell_values);
  vtkPointData* pd = ds->GetPointData();
  for (int i = 0; i < pd->GetNumberOfArrays(); ++i)
    if (vtkDataArray* a = pd->GetArray(i); a && a->GetNumberOfComponents() > 1) {
      auto& v = info.point_tuples[pd->GetArrayName(i)];
      for (vtkIdType k = 0; k < a->GetNumberOfTuples(); ++k)
        for (int c = 0; c < a->GetNumberOfComponents(); ++c)
          v.push_back(a->GetComponent(k, c));
    }
  vtkFieldData* fd = ds->GetFieldData();
  for (int i = 0; i < fd->GetNumberOfArrays(); ++i)
    if (vtkDataArray* a = fd->GetArray(i); a && a->GetNumberOfTuples() > 0) {
      info.field_values[fd->GetArrayName(i)] = a->GetComponent(0, 0);
      auto& v = info.field_tuples[fd->GetArrayName(i)];
      for (vtkIdType k = 0; k < a->GetNumberOfTuples(); ++k)
        for (int c = 0; c < a->GetNumberOfComponents(); ++c)
          v.push_back(a->GetComponent(k, c));
    }
  return info;
}

} // namespace rocklab
