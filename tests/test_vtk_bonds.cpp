// Every bonded contact model's bonds appear in the ParaView bond series (bonds_*.vtp), intact and
// then broken, with the model's registry index in the "model" cell array.
// The faced-grain cells file written in pieces equals the one written whole.
#include "helpers.hpp"

#include "contact/model_json.hpp"
#include "viz/vtk_output.hpp"

#include <nlohmann/json.hpp>

#include <fstream>
#include <random>

using namespace rocklab;
namespace fs = std::filesystem;

namespace {

struct BondedCase {
  std::string model;
  nlohmann::json props; ///< weak enough to break when the grains are pulled apart
};

// Two touching 2D grains with a bonded contact; grain 2 is pulled away along y at 1 m/s.
fs::path write_scene(const BondedCase& c) {
  const nlohmann::json scene = {
      {"dimension", 2},
      {"timestep", 1e-7},
      {"balls",
       {{{"id", 1}, {"position", {0, 0}}, {"radius", 1e-3}, {"density", 2650}, {"fix", "all"}},
        {{"id", 2},
         {"position", {0, 2e-3}},
         {"radius", 1e-3},
         {"density", 2650},
         {"velocity", {0, 1.0}},
         {"fix", "all"}}}},
      {"contact_models", {{{"between", "ball-ball"}, {"model", c.model}, {"properties", c.props}}}},
      {"run", {{"cycles", 1}}}};
  const fs::path file = test::scratch_root() / ("vtk-bonds-" + c.model + ".json");
  std::ofstream(file) << scene.dump(1);
  return file;
}

VtkFileInfo bonds_of(const Model& m, const std::string& name) {
  VtkSeries vtk(test::scratch_root() / ("vtk-bonds-" + name));
  const auto files = vtk.write(take_snapshot(m, {}, 0.0));
  return read_vtk_info((test::scratch_root() / ("vtk-bonds-" + name) / files[1]).string());
}

} // namespace

TEST(VtkBonds, EveryBondedModelIsDrawnIntactThenBroken) {
  const std::vector<BondedCase> cases = {
      {"linearpbond", {{"kn", 1e6}, {"pb_kn", 1e12}, {"pb_ks", 1e12}, {"pb_ten", 1e6}}},
      {"flatjoint",
       {{"fj_Nr", 2}, {"fj_kn", 1e12}, {"fj_ks", 1e12}, {"fj_ten", 1e6}, {"bond", true}}},
      {"smoothjoint",
       {{"sj_kn", 1e12}, {"sj_ks", 1e12}, {"sj_ten", 1e6}, {"sj_coh", 1e6}, {"bond", true}}},
      {"contactbond", {{"kn", 1e6}, {"cb_tenf", 10.0}, {"cb_shearf", 10.0}}},
      {"hysteretic", {{"hys_knm", 1e6}, {"hys_tenf", 10.0}}},
  };
  std::vector<std::string> covered;
  for (const BondedCase& c : cases) {
    SCOPED_TRACE(c.model);
    covered.push_back(c.model);
    Scene s = load_scene(write_scene(c).string());
    Model& m = *s.model;
    m.initialize();
    m.cycle(1);
    const double index = static_cast<double>(model_kind_of(c.model));
    VtkFileInfo v = bonds_of(m, c.model + "-intact");
    ASSERT_EQ(v.cells, 1);
    EXPECT_EQ(v.cell_values["model"], std::vector<double>{index});
    EXPECT_EQ(v.cell_values["bond_state"], std::vector<double>{2.0});
    EXPECT_EQ(v.cell_values["broken_fraction"], std::vector<double>{0.0});
    // Pulled apart by a tenth of a radius: the bond breaks; it is still drawn, as broken.
    m.cycle(1000);
    v = bonds_of(m, c.model + "-broken");
    ASSERT_EQ(v.cells, 1);
    EXPECT_EQ(v.cell_values["bond_state"], std::vector<double>{0.0});
    EXPECT_EQ(v.cell_values["broken_fraction"], std::vector<double>{1.0});
  }
  // Every model with a bond is covered: the others draw nothing.
  for (const std::string& name : model_names()) {
    if (std::find(covered.begin(), covered.end(), name) != covered.end())
      continue;
    SCOPED_TRACE(name);
    EXPECT_TRUE(name == "linear" || name == "powerplastic") << "a new model: add its bonded case";
  }
}

// The cells file is made and written a piece of grains at a time (memory at 10k grains, issue
// 15): cut into 7 pieces it holds the same polygons, fields and crack faces as in one piece.
TEST(VtkCells, APiecewiseCellsFileEqualsTheWholeOne) {
  nlohmann::json balls = nlohmann::json::array();
  const double d = 1e-3;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.1 * d, 0.1 * d);
  int id = 0;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      for (int k = 0; k < 6; ++k)
        balls.push_back(
            {{"id", ++id},
             {"position", {i * d + jitter(rng), j * d + jitter(rng), k * d + jitter(rng)}},
             {"radius", 0.35 * d},
             {"density", 2650},
             {"fix", "all"}});
  const nlohmann::json scene = {
      {"dimension", 3},
      {"timestep", 1e-7},
      {"balls", balls},
      {"contact_models",
       {{{"between", "ball-ball"}, {"model", "linear"}, {"properties", {{"kn", 1e6}}}}}},
      {"run", {{"cycles", 1}}}};
  const fs::path file = test::scratch_root() / "vtk-cells-scene.json";
  std::ofstream(file) << scene.dump(1);
  Scene s = load_scene(file.string());
  s.model->initialize();
  const Snapshot frame = take_snapshot(*s.model, {}, 0.0);
  // cracks between lattice neighbours along x: grain id n and n + 36
  const auto at = [&](double) {
    Snapshot c;
    c.dim = 3;
    for (std::int64_t n = 1; n <= 100; n += 9) {
      c.contact_cracks.push_back(CrackGlyph{});
      c.contact_crack_grains.push_back({n, n + 36});
    }
    return c;
  };
  struct Written {
    CellSummary sum;
    VtkFileInfo cells, faces;
  };
  const auto write = [&](const std::string& name, std::size_t per_piece) {
    const fs::path dir = test::scratch_root() / ("vtk-cells-" + name);
    fs::remove_all(dir);
    VtkSeries vtk(dir);
    vtk.set_cell_piece_grains(per_piece);
    vtk.write(frame);
    Written w;
    w.sum = vtk.write_fractures(at, true);
    w.cells = read_vtk_info((dir / "cells_0000.vtp").string());
    w.faces = read_vtk_info((dir / "contact_cracks_0000.vtp").string());
    return w;
  };
  const Written one = write("one", 1024), seven = write("seven", 31);
  EXPECT_EQ(one.sum.grains, 216u);
  EXPECT_GT(one.cells.cells, 6 * 216); // every cell has at least six faces
  EXPECT_EQ(seven.cells.cells, one.cells.cells);
  EXPECT_EQ(seven.cells.points, one.cells.points);
  EXPECT_EQ(seven.cells.positions, one.cells.positions);
  for (const char* a : {"grain", "cell_volume", "boundary", "radius"})
    EXPECT_EQ(seven.cells.cell_values.at(a), one.cells.cell_values.at(a)) << a;
  EXPECT_EQ(seven.sum.volume_sum, one.sum.volume_sum);
  EXPECT_EQ(seven.sum.hidden, one.sum.hidden);
  EXPECT_EQ(one.sum.faced_cracks, 12u); // every crack between neighbours is their shared face
  EXPECT_EQ(seven.sum.faced_cracks, one.sum.faced_cracks);
  EXPECT_EQ(seven.faces.positions, one.faces.positions);
}

// The crack series is written 4,096 cracks a piece: 10,000 disks come back whole and in order.
TEST(VtkCells, ACrackFileOfManyPiecesHoldsEveryCrackInOrder) {
  Snapshot frame;
  frame.dim = 3;
  frame.cracks.resize(10000);
  for (std::size_t k = 0; k < frame.cracks.size(); ++k) {
    frame.cracks[k].position = Vec3(1e-6 * static_cast<double>(k), 0, 0);
    frame.cracks[k].size = 1e-4;
    frame.cracks[k].time = static_cast<double>(k);
  }
  const fs::path dir = test::scratch_root() / "vtk-many-cracks";
  fs::remove_all(dir);
  VtkSeries(dir).write(frame);
  const fs::path file = dir / "cracks_0000.vtp";
  const VtkFileInfo v = read_vtk_info(file.string());
  ASSERT_EQ(v.cells, 10000);
  EXPECT_EQ(v.points, 16 * 10000);
  const std::vector<double>& time = v.cell_values.at("time");
  ASSERT_EQ(time.size(), 10000u);
  for (std::size_t k = 0; k < time.size(); ++k)
    ASSERT_EQ(time[k], static_cast<double>(k)) << k;
  EXPECT_NEAR(v.positions.back().x(), 1e-6 * 9999, 1e-4); // the last disk's rim
}
