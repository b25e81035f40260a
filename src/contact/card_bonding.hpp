// What a bonded contact model gives a material card (docs/material-format.md): the card section
// that names it, the per-contact distributions that section draws from, and the bond it makes at
// each bond candidate when genesis finalizes the specimen. A model that can bond a card's
// specimen declares, beside its other registry traits (contact_model.hpp):
//   static constexpr std::string_view card_section = "...";  // the card's key
//   static constexpr std::string_view card_counts[] = {...};  // what its bonds can be
//   static std::unique_ptr<CardBonding> card_bonding(JsonObject& top, int dim);
// and the card finds it through the registry (AllModels): adding one touches the model's files,
// its registration line and its docs, not the card or genesis. Units SI.
#pragma once

#include "contact/registry.hpp"
#include "io/json_input.hpp"

#include <initializer_list>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rocklab {

/// A property drawn per contact from Normal(mean, sd), clamped at zero.
struct Distribution {
  double mean = 0, sd = 0;
};

/// A card's distribution: a number (sd 0) or {"mean", "sd"} in `unit`, both >= 0; errors name the
/// file and key. For a key of a bonded model's own section, see read_card_section's drawn keys.
Distribution read_distribution(JsonObject& o, const std::string& key, const char* unit);

/// A key of a model's card section drawn per contact: the model's number or {"mean", "sd"}
/// around it (`field`: where the model's reader puts the number).
template <class M> struct DrawnKey {
  const char* key;
  double M::Props::*field;
  const char* unit;
};

/// A drawn key given as {"mean", "sd"}: the sd [unit, >= 0] is taken and `keys[key]` becomes the
/// mean, which the model's own reader then reads; a number or no key: sd 0.
double take_card_sd(nlohmann::json& keys, const std::string& file, const std::string& path,
                    const char* key, const char* unit);

/// The random values of one bond candidate: from the run's stream (the candidates shuffled) or
/// from a stream of the contact's own (`installation.draws`, materials/genesis/finalization.cpp).
class BondDraws {
public:
  virtual ~BondDraws() = default;
  /// One value of `d` (Normal, clamped at zero; the mean when sd is 0).
  virtual double normal(const Distribution& d) = 0;
  /// The category (0 .. fractions.size() - 1) of this candidate, by the card's fractions (summing
  /// to 1): by its rank among the shuffled candidates against the rounded counts (exact
  /// fractions), or by its own uniform (binomial fractions).
  virtual int category(std::span<const double> fractions) = 0;
};

/// One bond candidate: a grain-grain contact within the installation gap.
struct BondSite {
  double gap = 0;                      ///< the contact's gap [m]
  double r_avg = 0;                    ///< the card's mean grain radius [m]
  const LinearProps* linear = nullptr; ///< the card's `linear` section (a bond's linear part)
};

/// What a bond candidate becomes: the contact's model and which of the model's `card_counts` it
/// adds to (the genesis report's "<model>_<count>").
struct CardBond {
  ModelProps props;
  std::string_view count;
};

/// A card's bonding: its model's section, read once with the card (strengths as distributions).
class CardBonding {
public:
  virtual ~CardBonding() = default;
  /// The model every bond candidate gets, with its values drawn from `d` in a fixed order.
  virtual CardBond bond(BondDraws& d, const BondSite& site) const = 0;
  /// The section's model properties before any draw (the distributions' means).
  virtual ModelProps props() const = 0;
  /// The section's distributions by key (e.g. "fj_ten"), in reading order.
  virtual std::vector<std::pair<std::string, Distribution>> distributions() const = 0;
};

/// The model keys of a card section (read_card_section): a copy of the section without
/// `card_keys`, each key checked to start with `prefix`; the section is marked read in `top`.
nlohmann::json card_model_keys(JsonObject& top, const std::string& section,
                               const std::string& prefix,
                               std::initializer_list<const char*> card_keys);

/// Read a card section holding a contact model's properties: its model keys (all with `prefix`
/// in a bond section) by the model's own reader, the one a scene's contact_models entry uses
/// (one reader, one default per key), leaving out `card_keys` (types), which the section's caller
/// reads itself. Each of the `drawn` keys (a strength drawn per contact) is the model's own key:
/// its mean goes through the model's reader (range, default) and `drawn_out` receives the
/// distributions in the same order.
template <class M>
typename M::Props read_card_section(JsonObject& top, const std::string& section, int dim,
                                    const std::string& prefix,
                                    std::initializer_list<const char*> card_keys,
                                    std::initializer_list<DrawnKey<M>> drawn = {},
                                    std::vector<Distribution>* drawn_out = nullptr) {
  nlohmann::json keys = card_model_keys(top, section, prefix, card_keys);
  std::vector<double> sd;
  for (const DrawnKey<M>& d : drawn)
    sd.push_back(take_card_sd(keys, top.file(), top.key_path(section), d.key, d.unit));
  JsonObject model(keys, top.file(), top.key_path(section));
  typename M::Props p = M::read(model, dim);
  model.finish();
  if (drawn_out) {
    drawn_out->clear();
    std::size_t i = 0;
    for (const DrawnKey<M>& d : drawn)
      drawn_out->push_back({p.*(d.field), sd[i++]});
  }
  return p;
}

/// A point or parallel bond on the card's linear part (its own reference gap kept), bonded now
/// whatever the gap: the candidate test already applied g <= g_i.
template <class P> P bonded_on_card_linear(P props, const BondSite& site) {
  const double rgap = props.linear.rgap;
  props.linear = *site.linear;
  props.linear.rgap = rgap;
  props.bond = true;
  props.bond_gap_lo = -1e300;
  props.bond_gap_hi = 1e300;
  return props;
}

/// The models a card can bond with (the registry's models that declare the three traits above).
template <class M>
concept BondsCards = requires(JsonObject& top) {
  M::card_section;
  M::card_counts;
  M::card_bonding(top, 3);
};

} // namespace rocklab
