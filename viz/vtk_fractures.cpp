#include "io/output_dir.hpp"
#include "viz/nonaffine.hpp"
#include "viz/power_cells.hpp"
#include "viz/vtk_output.hpp"
#include "viz/vtk_write.hpp"

#include <vtkFloatArray.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPolyDataAlgorithm.h>
#include <vtkStreamingDemandDrivenPipeline.h>

#include <algorithm>
#include <functional>

#include <map>
#include <tuple>

namespace rocklab {

namespace vtkw {

namespace {

// A VTK source whose output is the piece the writer asks for: a file is then written a piece at
// a time, and only one piece's polygons are in memory at once.
class PieceSource : public vtkPolyDataAlgorithm {
public:
  static PieceSource* New();
  vtkTypeMacro(PieceSource, vtkPolyDataAlgorithm)
  std::function<void(int piece, int pieces, vtkPolyData* out)> make;

protected:
  PieceSource() { SetNumberOfInputPorts(0); }
  int RequestInformation(vtkInformation*, vtkInformationVector**,
                         vtkInformationVector* out) override {
    out->GetInformationObject(0)->Set(CAN_HANDLE_PIECE_REQUEST(), 1);
    return 1;
  }
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector* out) override {
    vtkInformation* info = out->GetInformationObject(0);
    make(info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()),
         info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()),
         vtkPolyData::GetData(info));
    return 1;
  }
};
vtkStandardNewMacro(PieceSource)

} // namespace

void write_poly_pieces(const std::filesystem::path& path, std::size_t items, std::size_t per_piece,
                       const std::function<void(std::size_t, std::size_t, PolyBuilder&)>& make) {
  per_piece = std::max<std::size_t>(per_piece, 1);
  const int pieces =
      static_cast<int>(std::max<std::size_t>(1, (items + per_piece - 1) / per_piece));
  vtkNew<PieceSource> source;
  source->make = [&](int piece, int count, vtkPolyData* out) {
    const auto at = [&](int p) {
      return items * static_cast<std::size_t>(p) / static_cast<std::size_t>(count);
    };
    PolyBuilder b;
    make(at(piece), at(piece + 1), b);
    out->ShallowCopy(b.pd);
  };
  write_xml<vtkXMLPolyDataWriter>(nullptr, path, source, pieces);
}

// Cracks [first, last) into b: 3D disks as 16-gons (or the given faces), 2D segments in the xy
// plane; per-contact cracks with their damage, event and energy.
void add_cracks(PolyBuilder& b, const std::vector<CrackGlyph>& cracks, std::size_t first,
                std::size_t last, const Snapshot& frame, bool per_contact,
                const std::vector<std::vector<Vec3>>* faces) {
  const int dim = frame.dim;
  add_frame_fields(b.pd, frame);
  std::vector<std::int32_t> mode, event, faced;
  std::vector<double> time, size, damage, energy;
  for (std::size_t k = first; k < last; ++k) {
    const CrackGlyph& c = cracks[k];
    const double r = 0.5 * c.size;
    const std::vector<Vec3>* face =
        faces && k < faces->size() && !(*faces)[k].empty() ? &(*faces)[k] : nullptr;
    faced.push_back(face != nullptr);
    if (face) { // the face the two grains' cells share (2D: an edge)
      std::vector<vtkIdType> ids;
      for (const Vec3& x : *face)
        ids.push_back(b.point(x));
      b.cells->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
    } else if (dim == 2) {
      const Vec3 t(-c.normal.y(), c.normal.x(), 0);
      const vtkIdType ids[2] = {b.point(c.position - r * t), b.point(c.position + r * t)};
      b.cells->InsertNextCell(2, ids);
    } else {
      Vec3 u, v;
      plane_axes(c.normal, u, v);
      constexpr int kSides = 16;
      vtkIdType ids[kSides];
      for (int side = 0; side < kSides; ++side) {
        const double a = 2 * kPi * side / kSides;
        ids[side] = b.point(c.position + r * (std::cos(a) * u + std::sin(a) * v));
      }
      b.cells->InsertNextCell(kSides, ids);
    }
    mode.push_back(c.mode);
    time.push_back(c.time);
    size.push_back(c.size);
    damage.push_back(c.damage);
    event.push_back(c.event);
    energy.push_back(c.energy);
  }
  b.cell_array<std::int32_t, vtkIntArray>("mode", mode);
  b.cell_array<double, vtkDoubleArray>("time", time);
  b.cell_array<double, vtkDoubleArray>("size", size);
  if (per_contact) {
    b.cell_array<double, vtkDoubleArray>("damage", damage);
    b.cell_array<std::int32_t, vtkIntArray>("event", event);
    b.cell_array<double, vtkDoubleArray>("energy", energy);
    if (faces)
      b.cell_array<std::int32_t, vtkIntArray>("faced", faced);
  }
  b.finish(dim == 2);
}

// Cracks: 3D disks as 16-gons, 2D segments in the xy plane; per-contact cracks with their damage,
// event and energy.
void write_cracks(const std::vector<CrackGlyph>& cracks, const Snapshot& frame, bool per_contact,
                  const std::filesystem::path& path, const std::vector<std::vector<Vec3>>* faces) {
  write_poly_pieces(path, cracks.size(), 4096,
                    [&](std::size_t first, std::size_t last, PolyBuilder& b) {
                      add_cracks(b, cracks, first, last, frame, per_contact, faces);
                    });
}

// Fracture events: one vertex per event at the centroid of its cracks; their sources' moment
// magnitude, type and R also as point data, for glyphs.
void write_events(const std::vector<EventGlyph>& events, const Snapshot& frame,
                  const std::filesystem::path& path) {
  PolyBuilder b;
  add_frame_fields(b.pd, frame);
  std::vector<std::int32_t> id, cracks, contacts;
  std::vector<double> time, duration, energy, magnitude, mw, r;
  std::vector<std::int32_t> type;
  vtkNew<vtkCellArray> verts;
  for (const EventGlyph& e : events) {
    const vtkIdType p = b.point(e.position);
    verts->InsertNextCell(1, &p);
    id.push_back(e.id);
    cracks.push_back(e.cracks);
    contacts.push_back(e.contacts);
    time.push_back(e.time);
    duration.push_back(e.duration);
    energy.push_back(e.energy);
    magnitude.push_back(e.magnitude);
    mw.push_back(e.moment_magnitude);
    type.push_back(e.source_type);
    r.push_back(e.r);
  }
  b.cell_array<std::int32_t, vtkIntArray>("event", id);
  b.cell_array<std::int32_t, vtkIntArray>("cracks", cracks);
  b.cell_array<std::int32_t, vtkIntArray>("contacts", contacts);
  b.cell_array<double, vtkDoubleArray>("time", time);
  b.cell_array<double, vtkDoubleArray>("duration", duration);
  b.cell_array<double, vtkDoubleArray>("energy", energy);
  b.cell_array<double, vtkDoubleArray>("magnitude", magnitude);
  b.point_array<double, vtkDoubleArray>("moment_magnitude", mw);
  b.point_array<std::int32_t, vtkIntArray>("source_type", type);
  b.point_array<double, vtkDoubleArray>("r_feignier_young", r);
  b.pd->SetPoints(b.pts);
  b.pd->SetVerts(verts);
  write_poly(b.pd, path);
}

} // namespace vtkw

namespace {

using namespace vtkw;

// One frame's grains read back from its grains file.
struct FrameGrains {
  VtkFileInfo info;
  std::map<std::int64_t, std::int64_t> index; ///< grain id -> point index
};

FrameGrains read_grains(const std::filesystem::path& file) {
  FrameGrains g;
  g.info = read_vtk_info(file.string());
  const auto& id = g.info.point_values["id"];
  for (std::size_t i = 0; i < id.size(); ++i)
    g.index[static_cast<std::int64_t>(id[i])] = static_cast<std::int64_t>(i);
  return g;
}

// Each grain's non-affine strain since the test began (viz/nonaffine.hpp), its neighbours those of
// the power diagram (grains either side of an opened crack stay neighbours), as a grain field the
// cells carry.
void add_nonaffine_strain(FrameGrains& g, const PowerDiagram& diagram, int dim) {
  const auto d = g.info.point_tuples.find("displacement");
  const std::size_t n = g.info.positions.size();
  if (d == g.info.point_tuples.end() || d->second.size() != 3 * n)
    return;
  std::vector<Vec3> disp(n);
  for (std::size_t i = 0; i < n; ++i)
    disp[i] = Vec3(d->second[3 * i], d->second[3 * i + 1], d->second[3 * i + 2]);
  g.info.point_values["nonaffine_strain"] =
      nonaffine_strain(g.info.positions, disp, diagram.neighbours(), dim);
}

// The cells of grains [first, first + cells.size()): 3D every face of every cell (so each grain
// is a closed polyhedron), 2D one polygon per cell; each carries its grain's index, id, cell
// volume, whether it lies on the specimen's boundary, and the grain's scalar fields (stresses,
// bond damage, ...).
void add_cells(PolyBuilder& b, const std::vector<PowerCell>& cells, std::size_t first,
               const FrameGrains& g, const Snapshot& frame) {
  add_frame_fields(b.pd, frame);
  std::vector<std::int32_t> grain, boundary;
  std::vector<double> volume;
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const PowerCell& c = cells[i];
    auto add = [&](const std::vector<Vec3>& poly, bool on_boundary) {
      std::vector<vtkIdType> ids;
      for (const Vec3& x : poly)
        ids.push_back(b.point(x));
      b.cells->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
      grain.push_back(static_cast<std::int32_t>(first + i));
      boundary.push_back(on_boundary);
      volume.push_back(c.volume);
    };
    if (frame.dim == 3) {
      for (std::size_t k = 0; k < c.faces.size(); ++k)
        add(c.faces[k], c.neighbour[k] < 0);
    } else if (!c.faces.empty()) {
      std::vector<Vec3> poly;
      bool edge = false;
      for (std::size_t k = 0; k < c.faces.size(); ++k)
        poly.push_back(c.faces[k][0]), edge = edge || c.neighbour[k] < 0;
      add(poly, edge);
    }
  }
  b.cell_array<std::int32_t, vtkIntArray>("grain", grain);
  b.cell_array<std::int32_t, vtkIntArray>("boundary", boundary);
  b.cell_array<double, vtkDoubleArray>("cell_volume", volume);
  vtkNew<vtkFloatArray> centre; // to cut the specimen along whole grains (a section view)
  centre->SetName("grain_center");
  centre->SetNumberOfComponents(3);
  for (const std::int32_t i : grain) {
    const Vec3& x = g.info.positions[static_cast<std::size_t>(i)];
    centre->InsertNextTuple3(x.x(), x.y(), x.z());
  }
  b.pd->GetCellData()->AddArray(centre);
  for (const auto& [name, values] : g.info.point_values) {
    std::vector<double> v;
    for (const std::int32_t i : grain)
      v.push_back(values[static_cast<std::size_t>(i)]);
    b.cell_array<double, vtkDoubleArray>(name.c_str(), v);
  }
  b.finish(false);
}

// The cells of one frame, written in pieces of `per_piece` grains; fills each contact crack's
// face (the face its two grains' cells share) and the summary on the way.
void write_cells(const PowerDiagram& diagram, const FrameGrains& g, const Snapshot& frame,
                 std::size_t per_piece, std::vector<std::vector<Vec3>>& faces, CellSummary& sum,
                 const std::filesystem::path& path) {
  const std::size_t n = diagram.size();
  // contact cracks as (point index of the first grain, crack, point index of the second), by the
  // first grain
  std::vector<std::tuple<std::int64_t, std::size_t, std::int64_t>> owned;
  for (std::size_t k = 0; k < frame.contact_cracks.size() && k < frame.contact_crack_grains.size();
       ++k) {
    const auto a = g.index.find(frame.contact_crack_grains[k][0]);
    const auto b = g.index.find(frame.contact_crack_grains[k][1]);
    if (a != g.index.end() && b != g.index.end())
      owned.emplace_back(a->second, k, b->second);
  }
  std::sort(owned.begin(), owned.end());
  std::vector<double> volume(n, 0.0); // summed in grain order below, as one pass would
  std::vector<char> hidden(n, 0);
  write_poly_pieces(path, n, per_piece, [&](std::size_t first, std::size_t last, PolyBuilder& b) {
    const std::vector<PowerCell> cells = diagram.cells(first, last);
    add_cells(b, cells, first, g, frame);
    for (std::size_t i = 0; i < cells.size(); ++i)
      volume[first + i] = cells[i].volume, hidden[first + i] = cells[i].faces.empty();
    const auto from = std::tuple{static_cast<std::int64_t>(first), std::size_t{0}, std::int64_t{0}};
    for (auto it = std::lower_bound(owned.begin(), owned.end(), from);
         it != owned.end() && std::get<0>(*it) < static_cast<std::int64_t>(last); ++it) {
      const auto [a, k, other] = *it;
      if (const auto* f = cells[static_cast<std::size_t>(a) - first].face_with(other))
        faces[k] = *f;
    }
  });
  sum.grains = n;
  for (std::size_t i = 0; i < n; ++i)
    sum.volume_sum += volume[i], sum.hidden += static_cast<std::size_t>(hidden[i]);
}

} // namespace

CellSummary VtkSeries::write_fractures(const std::function<Snapshot(double)>& at, bool with_cells) {
  std::filesystem::create_directories(dir_);
  CellSummary sum;
  for (const auto& [index, t] : snapshot_files()) {
    Snapshot s = at(t);
    FrameGrains g = read_grains(dir_ / ("grains_" + index + ".vtu"));
    s.step = static_cast<std::int64_t>(
        g.info.field_values.count("step") ? g.info.field_values.at("step") : 0);
    s.time = t;
    if (g.info.field_values.count("axial_strain"))
      s.axial_strain = g.info.field_values.at("axial_strain");
    if (g.info.field_values.count("axial_stress"))
      s.axial_stress = g.info.field_values.at("axial_stress");
    const std::vector<double>& radius = g.info.point_values.at("radius");
    ClipShape shape = ClipShape::around(g.info.positions, radius, s.dim, s.outline.round);
    if (const auto o = g.info.field_tuples.find("outline");
        o != g.info.field_tuples.end() && o->second.size() == 10) {
      const auto& v = o->second;
      shape.round = v[0] != 0;
      shape.lo = Vec3(v[1], v[2], v[3]), shape.hi = Vec3(v[4], v[5], v[6]);
      shape.center = Vec3(v[7], v[8], 0), shape.radius = v[9];
    }
    // each contact crack as its grains' shared face, where their cells touch
    std::vector<std::vector<Vec3>> faces(s.contact_cracks.size());
    CellSummary cell_sum;
    if (with_cells) {
      const PowerDiagram diagram(g.info.positions, radius, shape);
      add_nonaffine_strain(g, diagram, s.dim);
      write_cells(diagram, g, s, cell_piece_grains_, faces, cell_sum,
                  dir_ / ("cells_" + index + ".vtp"));
    }
    write_cracks(s.contact_cracks, s, true, dir_ / ("contact_cracks_" + index + ".vtp"), &faces);
    write_events(s.events, s, dir_ / ("events_" + index + ".vtp"));
    if (tagged_.contains(index))
      continue; // the summary is of the last numbered snapshot (the end of the test)
    sum = cell_sum;
    sum.shape_volume = with_cells ? shape.volume() : 0.0;
    sum.faced_cracks = static_cast<std::size_t>(
        std::count_if(faces.begin(), faces.end(), [](const auto& f) { return !f.empty(); }));
    sum.contact_cracks = s.contact_cracks.size();
  }
  fractures_ = true;
  cells_ = with_cells;
  return sum;
}

} // namespace rocklab
