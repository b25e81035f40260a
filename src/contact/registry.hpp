// The registry of contact models: the one type list of every model (AllModels) and what the engine
// and the file formats derive from it — the model kind of a contact, the per-model contiguous
// storage, the properties a rule assigns, and dispatch from a contact's kind to its model's
// functions (a chain of compares the compiler turns into a jump; no virtual call per contact).
#pragma once

#include "contact/contact_bond.hpp"
#include "contact/flat_joint.hpp"
#include "contact/hysteretic.hpp"
#include "contact/linear.hpp"
#include "contact/linear_pbond.hpp"
#include "contact/power_plastic.hpp"
#include "contact/smooth_joint.hpp"

#include <cassert>
#include <cstddef>
#include <span>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

namespace rocklab {

template <class... Ms> struct ModelList {};

/// Every contact model, once. Specimen files store a contact's model as its index here: append
/// new models at the end.
using AllModels =
    ModelList<Linear, LinearPBond, FlatJoint, SmoothJoint, Hysteretic, PowerPlastic, ContactBond>;

// ---------------------------------------------------------------------------------- the list

namespace registry_detail {
template <class List> struct Size;
template <class... Ms> struct Size<ModelList<Ms...>> {
  static constexpr std::size_t value = sizeof...(Ms);
};
template <std::size_t I, class List> struct At;
template <std::size_t I, class... Ms> struct At<I, ModelList<Ms...>> {
  using type = std::tuple_element_t<I, std::tuple<Ms...>>;
};
template <class M, class List> struct IndexOf;
template <class M, class... Ms> struct IndexOf<M, ModelList<Ms...>> {
  static constexpr std::size_t value = [] {
    constexpr bool same[] = {std::is_same_v<M, Ms>...};
    for (std::size_t i = 0; i < sizeof...(Ms); ++i)
      if (same[i])
        return i;
    return sizeof...(Ms);
  }();
};
template <class List> struct Apply;
template <class... Ms> struct Apply<ModelList<Ms...>> {
  using props = std::variant<typename Ms::Props...>;
  template <template <class> class B> using tuple = std::tuple<B<Ms>...>;
};
} // namespace registry_detail

inline constexpr std::size_t kModelCount = registry_detail::Size<AllModels>::value;
template <std::size_t I> using ModelAt = typename registry_detail::At<I, AllModels>::type;

/// The model of a contact: its index in AllModels (one byte in specimen files).
enum class ModelKind : std::uint8_t {};
template <class M>
inline constexpr ModelKind
    model_kind = static_cast<ModelKind>(registry_detail::IndexOf<M, AllModels>::value);

// ------------------------------------------------------------------- what a model provides

/// Models whose contacts share per-batch storage (flat-joint elements) get their part of it.
template <class M>
concept HasPool = requires {
  typename M::Pool;
};
template <class M>
concept HasMethods = requires {
  M::methods;
};
template <class M>
concept Inherits = requires(typename M::Props& p, const SurfaceProps& s) {
  M::inherit(p, s, s);
};
template <class M> constexpr bool allows_ball_facet() {
  if constexpr (requires { M::ball_facet; })
    return M::ball_facet;
  else
    return true;
}

/// Call f.template operator()<M>() with the model of kind k.
template <std::size_t I = 0, class F> decltype(auto) visit_model(ModelKind k, F&& f) {
  if constexpr (I == 0)
    assert(static_cast<std::size_t>(k) < kModelCount && "contact model kind out of range");
  if constexpr (I + 1 == kModelCount) {
    return f.template operator()<ModelAt<I>>();
  } else {
    if (static_cast<std::size_t>(k) == I)
      return f.template operator()<ModelAt<I>>();
    return visit_model<I + 1>(k, std::forward<F>(f));
  }
}

/// Call f.template operator()<M>() for every model, in list order.
template <class F> void for_each_model(F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f.template operator()<ModelAt<I>>(), ...);
  }
  (std::make_index_sequence<kModelCount>{});
}

/// The JSON keyword of a model kind.
inline std::string_view model_name(ModelKind k) {
  return visit_model(k, []<class M>() { return M::name; });
}

// ---------------------------------------------------------------------------------- storage

struct NoPool {
  void clear() {}
};
template <class M> struct PoolOf { using type = NoPool; };
template <HasPool M> struct PoolOf<M> { using type = typename M::Pool; };

/// One model's contacts in one contiguous array, plus the model's shared storage.
template <class M> struct Batch {
  std::vector<typename M::Contact> contacts;
  typename PoolOf<M>::type pool;
};

/// Capacity for n items and 1/16 more, when v has less (arrays rebuilt at each detection: growth
/// by doubling would leave up to twice the data allocated).
template <class V> void reserve_with_slack(V& v, std::size_t n) {
  if (v.capacity() < n)
    v.reserve(n + n / 16 + 64);
}

/// Per-model contiguous storage of contact data (parameters + state), indexed by a contact's slot.
struct ModelBatches {
  typename registry_detail::Apply<AllModels>::template tuple<Batch> all;

  template <class M> Batch<M>& of() { return std::get<Batch<M>>(all); }
  template <class M> const Batch<M>& of() const { return std::get<Batch<M>>(all); }
  void clear() {
    std::apply([](auto&... b) { ((b.contacts.clear(), b.pool.clear()), ...); }, all);
  }
  /// Capacity for the contents of `other` and 1/16 more: the list rebuilt at each detection is
  /// copied into these arrays, which grew by doubling without it (a 10k-grain flat-jointed
  /// specimen's set-up peaked at 55 MB in them against 22 MB of contact data).
  void reserve_like(const ModelBatches& other) {
    std::apply(
        [&](auto&... b) {
          (
              [&](auto& mine) {
                const auto& theirs = std::get<std::decay_t<decltype(mine)>>(other.all);
                reserve_with_slack(mine.contacts, theirs.contacts.size());
                if constexpr (requires { mine.pool.all; })
                  reserve_with_slack(mine.pool.all, theirs.pool.all.size());
              }(b),
              ...);
        },
        all);
  }
};

/// Call f(contact) or, for a model with a pool, f(contact, the contact's part of the pool).
template <class M, class B, class F> decltype(auto) with_contact(B& b, std::uint32_t slot, F&& f) {
  assert(slot < b.contacts.size() && "contact slot out of its batch");
  auto& c = b.contacts[slot];
  if constexpr (HasPool<M>)
    return f(c, b.pool.of(c));
  else
    return f(c);
}

/// Properties a rule assigns to a class of contacts; the alternative's index is the model kind.
using ModelProps = typename registry_detail::Apply<AllModels>::props;

inline ModelKind kind_of(const ModelProps& p) {
  return static_cast<ModelKind>(p.index());
}

/// Property inheritance from the two pieces' groups, for models that inherit.
inline void inherit_properties(ModelProps& props, const SurfaceProps& a, const SurfaceProps& b) {
  visit_model(kind_of(props), [&]<class M>() {
    if constexpr (Inherits<M>)
      M::inherit(std::get<typename M::Props>(props), a, b);
  });
}

// ------------------------------------------------------------------------ per-contact calls

inline std::uint32_t create_contact_data(ModelBatches& b, const ModelProps& props,
                                         const CreationInfo& ci) {
  return visit_model(kind_of(props), [&]<class M>() {
    Batch<M>& batch = b.of<M>();
    const auto& p = std::get<typename M::Props>(props);
    if constexpr (HasPool<M>)
      batch.contacts.push_back(M::make(p, ci, batch.pool));
    else
      batch.contacts.push_back(M::make(p, ci));
    return static_cast<std::uint32_t>(batch.contacts.size() - 1);
  });
}

/// Move the data of one contact into another batch set (used when the list is rebuilt).
inline std::uint32_t move_contact_data(ModelBatches& to, const ModelBatches& from, ModelKind kind,
                                       std::uint32_t slot) {
  return visit_model(kind, [&]<class M>() {
    Batch<M>& dst = to.of<M>();
    const Batch<M>& src = from.of<M>();
    if constexpr (HasPool<M>)
      dst.contacts.push_back(dst.pool.adopt(src.pool, src.contacts[slot]));
    else
      dst.contacts.push_back(src.contacts[slot]);
    return static_cast<std::uint32_t>(dst.contacts.size() - 1);
  });
}

/// Force-displacement update of one contact; out is in contact-plane coordinates.
inline void update_contact(ModelBatches& b, ModelKind kind, std::uint32_t slot,
                           const ContactKinematics& k, ContactResult& out, EventSink& ev) noexcept {
  visit_model(kind, [&]<class M>() {
    with_contact<M>(b.of<M>(), slot, [&](auto&&... c) { M::update(c..., k, out, ev); });
  });
}

inline ContactStiffness contact_stiffness(const ModelBatches& b, ModelKind kind,
                                          std::uint32_t slot) {
  return visit_model(kind, [&]<class M>() { return M::stiffness(b.of<M>().contacts[slot]); });
}

inline ContactEnergy contact_energy(const ModelBatches& b, ModelKind kind, std::uint32_t slot) {
  return visit_model(kind, [&]<class M>() {
    return with_contact<M>(b.of<M>(), slot, [&](const auto&... c) { return M::energy(c...); });
  });
}

inline bool contact_keeps_alive(const ModelBatches& b, ModelKind kind, std::uint32_t slot) {
  return visit_model(kind, [&]<class M>() {
    return with_contact<M>(b.of<M>(), slot, [&](const auto&... c) { return M::keeps_alive(c...); });
  });
}

/// The contact's bond as output shows it (no bond for models without one).
inline BondView contact_bond_view(const ModelBatches& b, ModelKind kind, std::uint32_t slot) {
  return visit_model(kind, [&]<class M>() {
    if constexpr (requires { &M::bond_view; })
      return with_contact<M>(b.of<M>(), slot, [&](const auto&... c) { return M::bond_view(c...); });
    else
      return BondView{};
  });
}

} // namespace rocklab
