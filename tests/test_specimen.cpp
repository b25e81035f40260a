// Specimen / checkpoint files: exact restore, deterministic bytes, clean failures.
#include "contact/model_json.hpp"
#include "helpers.hpp"
#include "io/json_input.hpp"
#include "io/results.hpp"
#include "io/specimen.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

namespace fs = std::filesystem;
using namespace rocklab;

namespace {
std::string state(const Model& m) {
  return results_json(m, {}, "x").dump();
}

// Settling grains with all four contact models in play: linear with walls, parallel bonds,
// flat joints and smooth joints between groups, under gravity and local damping.
std::unique_ptr<Model> busy_model() {
  Scene s = load_scene(test::source_dir() + "/examples/settling_2k.json");
  Model& m = *s.model;
  for (std::size_t i = 0; i < m.balls.size(); ++i)
    m.balls.group[i] = m.group_index(i % 3 == 0 ? "a" : (i % 3 == 1 ? "b" : "c"));
  FlatJointProps fj;
  fj.fj_kn = 2e7;
  fj.fj_ks = 1e7;
  fj.fj_ten = fj.fj_coh = 2e3;
  fj.fj_fric = 0.4;
  fj.bond = true;
  LinearPBondProps pb;
  pb.linear.kn = 2e4;
  pb.linear.ks = 1e4;
  pb.linear.fric = 0.5;
  pb.pb_kn = 1e7;
  pb.pb_ks = 5e6;
  pb.pb_ten = pb.pb_coh = 1e3;
  pb.bond_gap_hi = 1e-4;
  SmoothJointProps sj;
  sj.sj_kn = 1e7;
  sj.sj_ks = 5e6;
  sj.sj_fric = 0.3;
  sj.dip = 20;
  sj.ddir = 60;
  std::vector<ModelRule> rules;
  auto rule = [&](const char* g1, const char* g2, ModelProps p) {
    ModelRule r;
    r.group1 = m.group_index(g1);
    r.group2 = m.group_index(g2);
    r.props = p;
    rules.push_back(r);
  };
  rule("a", "a", fj);
  rule("b", "b", pb);
  rule("a", "b", sj);
  for (const ModelRule& r : m.rules)
    rules.push_back(r); // the scene's linear rules for everything else
  m.rules = rules;
  m.balls.track_orientation(true); // so that orientations are restored and validated too
  m.initialize();
  m.cycle(1500);
  return std::move(s.model);
}
} // namespace

namespace {
/// Each contact's model state (results.json's "state") and output by key.
std::map<std::uint64_t, std::string> contact_states(const Model& m) {
  std::map<std::uint64_t, std::string> out;
  for (std::size_t i = 0; i < m.contacts().size(); ++i) {
    const Contact& c = m.contacts()[i];
    const ContactOutput& o = m.contact_outputs()[i];
    std::ostringstream s;
    s.precision(17);
    s << model_name(c.model) << " " << o.xc.transpose() << " " << o.force.transpose() << " "
      << contact_state_json(m.batches(), c.model, c.slot, m.settings.dim).dump();
    out[c.key] = s.str();
  }
  return out;
}

/// Every model's slots count up from 0 in contact order, its batch holds nothing else, and the
/// flat joints' elements lie in slot order without holes.
::testing::AssertionResult packed(const Model& m) {
  std::array<std::uint32_t, kModelCount> next{};
  for (std::size_t i = 0; i < m.contacts().size(); ++i) {
    const Contact& c = m.contacts()[i];
    if (c.slot != next[static_cast<std::size_t>(c.model)]++)
      return ::testing::AssertionFailure() << "contact " << i << " has slot " << c.slot;
  }
  std::string bad;
  for_each_model([&]<class M>() {
    if (m.batches().of<M>().contacts.size() != next[static_cast<std::size_t>(model_kind<M>)])
      bad += std::string(M::name) + ": slots left over; ";
  });
  const Batch<FlatJoint>& fj = m.batches().of<FlatJoint>();
  if (!fj.pool.packed(fj.contacts))
    bad += "flat-joint elements not packed";
  if (!bad.empty())
    return ::testing::AssertionFailure() << bad;
  return ::testing::AssertionSuccess();
}

std::array<std::size_t, kModelCount> per_model(const Model& m) {
  std::array<std::size_t, kModelCount> n{};
  for (const Contact& c : m.contacts())
    ++n[static_cast<std::size_t>(c.model)];
  return n;
}
} // namespace

// The contact list is rebuilt in place at each detection (src/core/contact_list.cpp): the
// contacts that stay keep their data bit for bit while others are added in key order or removed
// around them, and every model's batch stays packed.
TEST(ContactList, ARebuildInPlaceKeepsEachContactsDataAndPacksTheBatches) {
  std::unique_ptr<Model> m = busy_model(); // 1,500 steps of detections behind it
  EXPECT_TRUE(packed(*m));
  const auto before = contact_states(*m);
  const auto n_before = per_model(*m);
  const double margin = m->margin();
  m->set_margin(4 * margin); // contacts added between the present ones
  EXPECT_TRUE(packed(*m));
  const auto wide = contact_states(*m);
  const auto n_wide = per_model(*m);
  const std::size_t fj = static_cast<std::size_t>(model_kind<FlatJoint>);
  EXPECT_GT(n_wide[fj], n_before[fj]);
  for (const auto& [key, s] : before) {
    ASSERT_TRUE(wide.count(key)) << "contact " << key << " lost";
    EXPECT_EQ(wide.at(key), s) << "contact " << key;
  }
  std::size_t added_fj = 0; // the added flat joints have their own data (Eq. 30's radius)
  for (const Contact& c : m->contacts())
    if (c.model == model_kind<FlatJoint> && !before.count(c.key)) {
      const auto& fjc = m->batches().of<FlatJoint>().contacts[c.slot];
      const double R1 = m->balls.radius[static_cast<std::size_t>(c.end1)];
      const double R2 = m->balls.radius[static_cast<std::size_t>(c.end2)];
      EXPECT_EQ(fjc.R, fjc.rmul * std::min(R1, R2)) << "contact " << c.key;
      ++added_fj;
    }
  EXPECT_GT(added_fj, 1u);
  m->set_margin(margin); // the ones out of reach go again
  EXPECT_TRUE(packed(*m));
  const auto back = contact_states(*m);
  EXPECT_LT(back.size(), wide.size());
  for (const auto& [key, s] : back) {
    ASSERT_TRUE(wide.count(key)) << "contact " << key << " appeared";
    EXPECT_EQ(wide.at(key), s) << "contact " << key;
  }
  // Removing every fifth ball drops flat joints among the others (the pool compacted in place);
  // the rest keep their order and data under renumbered ends.
  std::vector<bool> remove(m->balls.size());
  for (std::size_t i = 0; i < remove.size(); i += 5)
    remove[i] = m->balls.clump[i] < 0;
  std::vector<std::string> staying;
  const auto fj_before = per_model(*m)[fj];
  const auto present = contact_states(*m);
  for (const Contact& c : m->contacts())
    if (!remove[static_cast<std::size_t>(c.end1)] &&
        (c.kind != ContactKind::BallBall || !remove[static_cast<std::size_t>(c.end2)]))
      staying.push_back(present.at(c.key));
  m->remove_balls(remove);
  EXPECT_TRUE(packed(*m));
  EXPECT_LT(per_model(*m)[fj], fj_before);
  ASSERT_GE(m->contacts().size(), staying.size());
  const auto after = contact_states(*m);
  std::size_t k = 0; // remove_balls re-detects: contacts may be added, none of the old ones lost
  for (const Contact& c : m->contacts())
    if (k < staying.size() && after.at(c.key) == staying[k])
      ++k;
  EXPECT_EQ(k, staying.size());
  // A replaced contact model leaves its old data behind; the next rebuild packs the batches.
  LinearProps lin;
  lin.kn = 1e5;
  auto gap = [&](const Contact& c) { // (new contacts' gap fields are set by their first update)
    const auto i = static_cast<std::size_t>(c.end1), j = static_cast<std::size_t>(c.end2);
    return (m->balls.pos[i] - m->balls.pos[j]).norm() - m->balls.radius[i] - m->balls.radius[j];
  };
  const auto closest_fj = std::min_element(
      m->contacts().begin(), m->contacts().end(), [&](const Contact& x, const Contact& y) {
        const bool fx = x.model == model_kind<FlatJoint>, fy = y.model == model_kind<FlatJoint>;
        return fx != fy ? fx : gap(x) < gap(y);
      });
  ASSERT_EQ(closest_fj->model, model_kind<FlatJoint>);
  const std::uint64_t key = closest_fj->key;
  m->replace_contact_model(static_cast<std::size_t>(closest_fj - m->contacts().begin()), lin);
  EXPECT_FALSE(packed(*m));
  m->set_margin(margin);
  EXPECT_TRUE(packed(*m));
  EXPECT_EQ(contact_states(*m).at(key).rfind("linear ", 0), 0u);
}

TEST(Specimen, RoundTripContinuesBitForBit) {
  std::unique_ptr<Model> a = busy_model();
  ASSERT_GT(a->batches().of<FlatJoint>().contacts.size(), 0u);
  ASSERT_GT(a->batches().of<LinearPBond>().contacts.size(), 0u);
  ASSERT_GT(a->batches().of<SmoothJoint>().contacts.size(), 0u);
  const fs::path file = rocklab::test::scratch_root() / "rocklab-roundtrip.rlspec";
  save_model(*a, file.string(), {{"note", "test"}});
  nlohmann::json meta;
  std::unique_ptr<Model> b = load_model(file.string(), &meta);
  EXPECT_EQ(meta["note"], "test");
  EXPECT_EQ(state(*a), state(*b));
  a->cycle(1000);
  b->cycle(1000);
  EXPECT_EQ(state(*a), state(*b));
  EXPECT_EQ(a->step(), b->step());
  // Saving the restored model gives the same bytes.
  const fs::path again = rocklab::test::scratch_root() / "rocklab-roundtrip-2.rlspec";
  std::unique_ptr<Model> c = load_model(file.string());
  save_model(*c, again.string(), {{"note", "test"}});
  EXPECT_EQ(test::read_file(file), test::read_file(again));
}

// Grains pressed against an exact cylinder wall (a genesis vessel, a triaxial sleeve): their
// contacts carry facet 0 of a wall with no facets, which loading once rejected as "facet out of
// range" (a 3D calibration's packing cache could not be read back).
TEST(Specimen, ContactsWithAnExactCylinderWallRoundTrip) {
  auto a = std::make_unique<Model>();
  a->settings.dim = 3;
  a->settings.gravity = Vec3(0, 0, -9.81);
  const auto g = a->group_index("rock");
  const double R = 1e-3, Rc = 3.2e-3;
  std::int64_t id = 1;
  for (int layer = 0; layer < 3; ++layer)
    for (int k = 0; k < 6; ++k) {
      const double t = 2 * M_PI * k / 6 + 0.5 * layer;
      a->balls.add(3, id++,
                   Vec3((Rc - R) * std::cos(t), (Rc - R) * std::sin(t), (2 * layer + 1) * R), R,
                   2600, g);
      a->balls.vel.back() = Vec3(0.05 * std::cos(t), 0.05 * std::sin(t), 0); // onto the sleeve
    }
  Wall sleeve;
  sleeve.name = "sleeve";
  sleeve.cylinder_radius = Rc;
  sleeve.half_height = 0.02;
  sleeve.update_bounds();
  a->walls.push_back(sleeve);
  a->walls.push_back(rocklab::plane_wall(3, "floor", Vec3::Zero(), Vec3::UnitZ(), 0.02));
  LinearProps lp;
  lp.kn = 1e5;
  lp.ks = 5e4;
  lp.fric = 0.5;
  a->rules.push_back(test::linear_rule(false, lp));
  a->rules.push_back(test::linear_rule(true, lp));
  a->initialize();
  a->cycle(2000);
  std::size_t on_sleeve = 0;
  for (const Contact& c : a->contacts())
    on_sleeve += c.kind == ContactKind::BallFacet && c.end2 == 0;
  ASSERT_GT(on_sleeve, 0u);
  const fs::path file = rocklab::test::scratch_root() / "rocklab-cylinder.rlspec";
  save_model(*a, file.string(), {});
  std::unique_ptr<Model> b = load_model(file.string());
  EXPECT_EQ(state(*a), state(*b));
  a->cycle(500);
  b->cycle(500);
  EXPECT_EQ(state(*a), state(*b));
}

TEST(Specimen, BadFilesFailCleanly) {
  const fs::path dir = rocklab::test::scratch_root();
  EXPECT_THROW(load_model((dir / "does-not-exist.rlspec").string()), InputError);
  const fs::path notjson = dir / "rocklab-notjson.rlspec";
  std::ofstream(notjson) << "hello\n";
  try {
    load_model(notjson.string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a rocklab specimen"), std::string::npos);
  }
  // A truncated body.
  std::unique_ptr<Model> m = busy_model();
  const fs::path file = dir / "rocklab-trunc.rlspec";
  save_model(*m, file.string());
  std::string bytes = test::read_file(file);
  std::ofstream(file, std::ios::binary) << bytes.substr(0, bytes.size() - 100);
  try {
    load_model(file.string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  // A newer version.
  const std::string cur = "\"version\":" + std::to_string(kSpecimenVersion);
  bytes.replace(bytes.find(cur), cur.size(), "\"version\":99");
  std::ofstream(file, std::ios::binary) << bytes;
  try {
    load_model(file.string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("key 'version'"), std::string::npos) << e.what();
  }
}

// Specimen and checkpoint files carry a checksum of their body (a changed byte is named as such)
// and are validated field by field on load, so a body changed and re-hashed still cannot crash a
// run: every mutant loads and runs, or fails with an InputError naming the file.
TEST(Specimen, ChangedBytesFailTheChecksumAndCorruptFieldsFailValidation) {
  const fs::path dir = rocklab::test::scratch_root();
  std::unique_ptr<Model> m = busy_model();
  const fs::path file = dir / "rocklab-checksum.rlspec";
  save_model(*m, file.string());
  const std::string bytes = test::read_file(file);
  const std::size_t eol = bytes.find('\n');
  nlohmann::json header = nlohmann::json::parse(bytes.substr(0, eol));
  const std::string body = bytes.substr(eol + 1);
  ASSERT_EQ(header["body_fnv1a64"], text_hash(body));
  auto expect_error = [&](const std::string& text, const std::string& what) {
    std::ofstream(file, std::ios::binary) << text;
    try {
      load_model(file.string());
      ADD_FAILURE() << "loaded; expected: " << what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    }
  };
  std::string flipped = bytes;
  flipped[eol + 1 + body.size() / 2] ^= 0x01; // one bit of one byte in the middle of the body
  expect_error(flipped, "does not match its checksum");
  nlohmann::json h = header;
  h["version"] = "6";
  expect_error(h.dump() + "\n" + body, "key 'version'");
  h = header;
  h.erase("body_fnv1a64");
  expect_error(h.dump() + "\n" + body, "key 'body_fnv1a64'");
  h = header;
  h["meta"] = {{"peak", nlohmann::json::array()}}; // a checkpoint's machine state edited
  expect_error(h.dump() + "\n" + body, "key 'meta' does not match its checksum");
  // Mutants whose checksum is made to match: 1-4 random bytes changed (fixed seed).
  std::mt19937_64 rng(20261202);
  int loaded = 0, rejected = 0;
  for (int k = 0; k < 200; ++k) {
    std::string b = body;
    const int changes = 1 + static_cast<int>(rng() % 4);
    for (int c = 0; c < changes; ++c)
      b[rng() % b.size()] = static_cast<char>(rng() & 0xff);
    h = header;
    h["body_fnv1a64"] = text_hash(b);
    std::ofstream(file, std::ios::binary) << h.dump() << '\n' << b;
    try {
      std::unique_ptr<Model> x = load_model(file.string());
      ++loaded;
      try {
        x->cycle(10); // a state that loads must run (or stop with a clean error)
      } catch (const std::exception&) {
      }
    } catch (const InputError& e) {
      ++rejected;
      EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(loaded + rejected, 200);
  EXPECT_GT(rejected, 0);
  std::printf("re-hashed mutants: %d loaded and ran, %d rejected\n", loaded, rejected);
}

// results.json is streamed item by item (a 10k-sphere flat-jointed model's list was ~1.5 GB as a
// document in memory): the stream is the document's own dump(1) text plus the contact count, and
// the per-contact list is opt-in above kContactsAutoLimit contacts or when a scene says so.
TEST(Specimen, ResultsAreStreamedAsTheDocumentAndLargeContactListsAreOptIn) {
  std::unique_ptr<Model> m = busy_model();
  m->cycle(50);
  ASSERT_GT(m->contacts().size(), 10u);
  nlohmann::json doc = results_json(*m, {}, "x");
  doc["contact_count"] = m->contacts().size();
  std::ostringstream full;
  write_results_json(full, *m, {}, "x", ContactOutputMode::Auto);
  EXPECT_EQ(full.str(), doc.dump(1) + "\n");
  std::ostringstream none;
  write_results_json(none, *m, {}, "x", ContactOutputMode::Never);
  const nlohmann::json n = nlohmann::json::parse(none.str());
  EXPECT_FALSE(n.contains("contacts"));
  EXPECT_TRUE(n["contacts_omitted"].is_string());
  EXPECT_EQ(n["balls"], doc["balls"]);
  EXPECT_TRUE(contacts_written(ContactOutputMode::Auto, kContactsAutoLimit));
  EXPECT_FALSE(contacts_written(ContactOutputMode::Auto, kContactsAutoLimit + 1));
  EXPECT_TRUE(contacts_written(ContactOutputMode::Always, kContactsAutoLimit + 1));
  // The scene key.
  nlohmann::json scene = nlohmann::json::parse(
      std::ifstream(test::source_dir() + "/examples/two_ball_collision.json"));
  const std::string path = (test::scratch_root() / "output_contacts.json").string();
  for (const bool want : {true, false}) {
    scene["output"] = {{"contacts", want}};
    std::ofstream(path) << scene.dump();
    EXPECT_EQ(load_scene(path).contacts_output,
              want ? ContactOutputMode::Always : ContactOutputMode::Never);
  }
  scene["output"] = {{"contacts", "yes"}};
  std::ofstream(path) << scene.dump();
  EXPECT_THROW(load_scene(path), InputError);
}
