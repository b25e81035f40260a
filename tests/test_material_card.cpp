// The material card reads contact-model keys through the models' own readers (issue 41): the same
// key has the same default and range in a card and in a scene, the keys genesis sets are refused
// on a card, and factors a contact divides by have a positive lower bound.
#include "contact/model_json.hpp"
#include "helpers.hpp"
#include "io/input_error.hpp"
#include "io/json_input.hpp"
#include "materials/material_card.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <thread>

namespace fs = std::filesystem;
using namespace rocklab;
using nlohmann::json;

namespace {

// A small 2D card with `section` replaced (or added), written to the scratch folder.
std::string card_with(const std::string& section, const json& value, int dim = 2) {
  json c = {{"name", "card-test"},
            {"units", "SI"},
            {"dimension", dim},
            {"density", 2650},
            {"grains", {{"radius", {0.001, 0.0015}}}},
            {"porosity", 0.2},
            {"specimen", dim == 2 ? json{{"shape", "rectangle"}, {"width", 0.03}, {"height", 0.06}}
                                  : json{{"shape", "prism"}, {"size", {0.03, 0.03, 0.06}}}},
            {"linear", {{"emod", 1e9}, {"kratio", 1.5}, {"fric", 0.5}}}};
  c[section] = value;
  const fs::path p =
      test::scratch_root() / ("card-" + section + "-" + std::to_string(dim) + ".json");
  std::ofstream(p) << c.dump(1);
  return p.string();
}

// The InputError message of reading a card (empty when it reads).
std::string card_error(const std::string& file) {
  try {
    load_material_card(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A scene's reading of the same model keys.
template <class M> typename M::Props scene_read(const json& keys, int dim) {
  JsonObject o(keys, "scene.json", "contact_models[0].properties");
  typename M::Props p = M::read(o, dim);
  o.finish();
  return p;
}

// A card's bond section as its model read it: the properties and the distributions by key.
template <class P> struct BondSection {
  P props;
  std::map<std::string, Distribution> dist;
};
template <class P> BondSection<P> bond_section(const MaterialCard& card) {
  BondSection<P> s{std::get<P>(card.bonding->props()), {}};
  for (const auto& [key, d] : card.bonding->distributions())
    s.dist[key] = d;
  return s;
}

} // namespace

TEST(MaterialCard, ModelKeysMeanTheSameInACardAndInAScene) {
  for (int dim : {2, 3}) {
    // Defaults: a card giving only a stiffness and strengths takes the model's defaults, as a
    // scene does (fj_Nr 2 in 2D too: the memo's Table 5, where a 2D card used to say 4).
    const json fj = {{"fj_emod", 2e9}, {"fj_ten", 1e6}, {"fj_coh", 2e6}};
    const MaterialCard card = load_material_card(card_with("flatjoint", fj, dim));
    const auto c = bond_section<FlatJointProps>(card);
    const FlatJointProps s = scene_read<FlatJoint>({{"fj_emod", 2e9}}, dim);
    EXPECT_EQ(c.props.fj_Nr, 2);
    EXPECT_EQ(c.props.fj_Nr, s.fj_Nr);
    EXPECT_EQ(c.props.fj_Nal, s.fj_Nal);
    EXPECT_EQ(c.props.fj_kratio, 0.0); // was required on a card
    EXPECT_EQ(c.props.fj_kratio, s.fj_kratio);
    EXPECT_EQ(c.props.fj_rmul, s.fj_rmul);
    EXPECT_EQ(c.props.fj_fric, s.fj_fric);
    EXPECT_EQ(c.props.fj_fa, s.fj_fa);
    EXPECT_EQ(c.props.fj_exact, s.fj_exact);
    EXPECT_EQ(c.dist.at("fj_ten").mean, 1e6);
    EXPECT_EQ(c.dist.at("fj_coh").mean, 2e6);
    // Given values arrive unchanged, and the stiffness pair may be given either way.
    json given = {{"fj_Nr", 3},
                  {"fj_rmul", 0.8},
                  {"fj_kn", 4e12},
                  {"fj_ks", 2e12},
                  {"fj_fric", 0.4},
                  {"fj_fa", 25.0},
                  {"fj_ten", {{"mean", 1e6}, {"sd", 1e5}}},
                  {"fj_coh", 3e6}};
    if (dim == 3)
      given["fj_Nal"] = 6;
    const auto g =
        bond_section<FlatJointProps>(load_material_card(card_with("flatjoint", given, dim)));
    json scene_keys = given;
    scene_keys.erase("fj_ten");
    scene_keys.erase("fj_coh");
    const FlatJointProps gs = scene_read<FlatJoint>(scene_keys, dim);
    EXPECT_EQ(g.props.fj_Nr, 3);
    EXPECT_EQ(g.props.fj_Nal, dim == 3 ? 6 : gs.fj_Nal);
    EXPECT_EQ(g.props.fj_Nal, gs.fj_Nal);
    EXPECT_EQ(g.props.fj_rmul, 0.8);
    EXPECT_EQ(g.props.fj_kn, 4e12);
    EXPECT_EQ(g.props.fj_ks, gs.fj_ks);
    EXPECT_EQ(g.props.fj_emod, 0.0);
    EXPECT_EQ(g.props.fj_fa, 25.0);
    EXPECT_EQ(g.dist.at("fj_ten").sd, 1e5);
    // Parallel bonds likewise (pb_kratio was required on a card, 0 in a scene).
    const auto p = bond_section<LinearPBondProps>(load_material_card(
        card_with("parallelbond", {{"pb_emod", 5e10}, {"pb_ten", 1e7}, {"pb_coh", 2e7}}, dim)));
    const LinearPBondProps ps = scene_read<LinearPBond>({{"pb_emod", 5e10}}, dim);
    EXPECT_EQ(p.props.pb_kratio, ps.pb_kratio);
    EXPECT_EQ(p.props.pb_mcf, ps.pb_mcf);
    EXPECT_EQ(p.props.pb_rmul, ps.pb_rmul);
    EXPECT_EQ(p.dist.at("pb_ten").mean, 1e7);
    // The linear section is the linear model's keys, those a scene may give included.
    const MaterialCard l = load_material_card(
        card_with("linear", {{"kn", 1e7}, {"ks", 5e6}, {"fric", 0.3}, {"rgap", 1e-6}}, dim));
    EXPECT_EQ(l.linear.kn, 1e7);
    EXPECT_EQ(l.linear.rgap, 1e-6);
  }
}

TEST(MaterialCard, KeysGenesisSetsAndMissingStiffnessAreRefusedNamingTheKey) {
  const json strengths = {{"fj_emod", 1e9}, {"fj_ten", 1e6}, {"fj_coh", 1e6}};
  json bond = strengths;
  bond["bond"] = true;
  EXPECT_NE(card_error(card_with("flatjoint", bond)).find("'flatjoint.bond'"), std::string::npos);
  json gap = strengths;
  gap["fj_gap0"] = 1e-5;
  EXPECT_NE(card_error(card_with("flatjoint", gap)).find("'flatjoint.fj_gap0'"), std::string::npos);
  // A linear key in the bond's section: the linear part is the card's `linear`.
  const std::string lin = card_error(card_with(
      "parallelbond", {{"pb_emod", 1e9}, {"pb_ten", 1e6}, {"pb_coh", 1e6}, {"fric", 0.3}}));
  EXPECT_NE(lin.find("'parallelbond.fric'"), std::string::npos) << lin;
  EXPECT_NE(lin.find("'linear'"), std::string::npos) << lin;
  // A card's bond needs a stiffness; both ways of giving it at once are refused.
  EXPECT_NE(card_error(card_with("flatjoint", {{"fj_ten", 1e6}, {"fj_coh", 1e6}}))
                .find("'flatjoint.fj_emod'"),
            std::string::npos);
  const std::string both = card_error(card_with(
      "parallelbond", {{"pb_emod", 1e9}, {"pb_kn", 1e12}, {"pb_ten", 1e6}, {"pb_coh", 1e6}}));
  EXPECT_NE(both.find("not both"), std::string::npos) << both;
  // An unknown model key is refused by the model's reader, with the card's key path.
  json typo = strengths;
  typo["fj_tens"] = 1e6;
  EXPECT_NE(card_error(card_with("flatjoint", typo)).find("flatjoint.fj_tens"), std::string::npos);
  // One bonded model per card, whichever two are given; the error names both.
  json both_models = read_json_file(card_with("flatjoint", strengths));
  both_models["contactbond"] = {{"cb_tenf", 1.0}, {"cb_shearf", 1.0}};
  const fs::path two = test::scratch_root() / "card-two-bonded-models.json";
  std::ofstream(two) << both_models.dump(1);
  const std::string two_error = card_error(two.string());
  EXPECT_NE(two_error.find("'flatjoint' and 'contactbond'"), std::string::npos) << two_error;
  // 2D flat joints have no circumferential elements.
  json nal = strengths;
  nal["fj_Nal"] = 4;
  EXPECT_NE(card_error(card_with("flatjoint", nal)).find("3D property"), std::string::npos);
}

TEST(MaterialCard, ADrawnStrengthIsTheModelsOwnKeyWithItsRangeAndDefault) {
  // The card's {"mean", "sd"} goes through the model's reader: its range names the key...
  const std::string negative = card_error(card_with(
      "flatjoint", {{"fj_emod", 1e9}, {"fj_ten", {{"mean", -1.0}, {"sd", 0.0}}}, {"fj_coh", 1e6}}));
  EXPECT_NE(negative.find("'flatjoint.fj_ten'"), std::string::npos) << negative;
  EXPECT_NE(negative.find("[0, +inf)"), std::string::npos) << negative;
  const std::string sd = card_error(
      card_with("parallelbond",
                {{"pb_emod", 1e9}, {"pb_ten", 1e6}, {"pb_coh", {{"mean", 1e6}, {"sd", -1.0}}}}));
  EXPECT_NE(sd.find("'parallelbond.pb_coh.sd'"), std::string::npos) << sd;
  // ... and a key the card leaves out takes the model's default, as in a scene (no sd).
  const MaterialCard c = load_material_card(
      card_with("flatjoint", {{"fj_emod", 1e9}, {"fj_coh", {{"mean", 2e6}, {"sd", 3e5}}}}));
  const auto& fj = bond_section<FlatJointProps>(c);
  EXPECT_EQ(fj.dist.at("fj_ten").mean, scene_read<FlatJoint>({{"fj_emod", 1e9}}, 3).fj_ten);
  EXPECT_EQ(fj.dist.at("fj_ten").sd, 0.0);
  EXPECT_EQ(fj.dist.at("fj_coh").mean, 2e6);
  EXPECT_EQ(fj.dist.at("fj_coh").sd, 3e5);
}

TEST(MaterialCard, FactorsAContactDividesByHaveAPositiveLowerBound) {
  // fuzz finding: fj_rmul = 1e-320 was accepted and the run ended with a NaN energy ledger.
  json fj = {{"fj_emod", 1e9}, {"fj_ten", 1e6}, {"fj_coh", 1e6}, {"fj_rmul", 1e-320}};
  const std::string e = card_error(card_with("flatjoint", fj));
  EXPECT_NE(e.find("'flatjoint.fj_rmul'"), std::string::npos) << e;
  EXPECT_NE(e.find("0.001"), std::string::npos) << e;
  EXPECT_THROW(scene_read<FlatJoint>({{"fj_kn", 1e9}, {"fj_rmul", 1e-320}}, 2), InputError);
  EXPECT_THROW(scene_read<LinearPBond>({{"pb_kn", 1e9}, {"pb_rmul", 1e-4}}, 3), InputError);
  EXPECT_NO_THROW(scene_read<LinearPBond>({{"pb_kn", 1e9}, {"pb_rmul", 1e-3}}, 3));
  // kratio divides kn: 0 (no shear stiffness) or at least 1e-3, for every model.
  EXPECT_THROW(scene_read<Linear>({{"emod", 1e9}, {"kratio", 1e-9}}, 2), InputError);
  EXPECT_THROW(scene_read<FlatJoint>({{"fj_emod", 1e9}, {"fj_kratio", 1e-300}}, 2), InputError);
  EXPECT_NO_THROW(scene_read<FlatJoint>({{"fj_emod", 1e9}, {"fj_kratio", 0.0}}, 2));
}

TEST(MaterialCard, AnInputGivenAsTextReadsLikeItsFileAndIsNamedInErrors) {
  // The Python module's dicts: the text under a name is read by the same loader as a file.
  const std::string file = test::source_dir() + "/tests/data/lab_2d_fj.json";
  json card = read_json_file(file);
  const MaterialCard from_file = load_material_card(file);
  {
    const InputText given("<card dict>", card.dump());
    const MaterialCard from_text = load_material_card("<card dict>");
    EXPECT_EQ(from_text.name, from_file.name);
    EXPECT_EQ(from_text.porosity, from_file.porosity);
    EXPECT_EQ(bond_section<FlatJointProps>(from_text).dist.at("fj_ten").mean,
              bond_section<FlatJointProps>(from_file).dist.at("fj_ten").mean);
    card["porosity"] = 1.5;
    const InputText inner("<card dict>", card.dump()); // the latest given wins
    try {
      load_material_card("<card dict>");
      ADD_FAILURE() << "a porosity of 1.5 was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("<card dict>: key 'porosity'", 0), 0u) << e.what();
    }
  }
  // Gone with its scope, and never seen by another thread.
  EXPECT_THROW(load_material_card("<card dict>"), InputError);
  const InputText given("<card dict>", read_input_text(file));
  bool other_thread_threw = false;
  std::thread([&] {
    try {
      read_input_text("<card dict>");
    } catch (const InputError&) {
      other_thread_threw = true;
    }
  }).join();
  EXPECT_TRUE(other_thread_threw);
}
