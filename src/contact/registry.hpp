// Registry of contact models: one enum value, one batch, one props alternative per model.
// Adding a model = its file pair + one line in each of the three lists below + its overloads.
#pragma once

#include "contact/linear.hpp"

#include <string_view>
#include <variant>
#include <vector>

namespace rocklab {

enum class ModelKind : std::uint8_t { Linear };

inline constexpr std::string_view model_name(ModelKind k) {
  switch (k) {
  case ModelKind::Linear:
    return "linear";
  }
  return "unknown";
}

/// Per-model contiguous storage of contact data (properties + state).
struct ModelBatches {
  std::vector<LinearContact> linear;

  void clear() { linear.clear(); }
};

/// Properties a scene assigns to a class of contacts; the alternative selects the model.
using ModelProps = std::variant<LinearProps>;

inline ModelKind kind_of(const ModelProps& p) {
  return static_cast<ModelKind>(p.index());
}

/// Call f with the contact data of the given model kind and slot.
template <class Batches, class F>
decltype(auto) visit_contact(Batches& b, ModelKind kind, std::uint32_t slot, F&& f) {
  switch (kind) {
  case ModelKind::Linear:
    return f(b.linear[slot]);
  }
  __builtin_unreachable();
}

// Uniform overloads used by the engine.
inline void update_contact(LinearContact& c, const ContactKinematics& k, ContactResult& out,
                           EventSink& ev) noexcept {
  linear::update(c, k, out, ev);
}
inline ContactStiffness contact_stiffness(const LinearContact& c) {
  return linear::stiffness(c);
}
inline ContactEnergy contact_energy(const LinearContact& c) {
  return linear::energy(c);
}
inline bool contact_keeps_alive(const LinearContact& c) {
  return linear::keeps_alive(c);
}

/// Build the per-contact data for a new contact from the assigned properties.
inline std::uint32_t create_contact_data(ModelBatches& b, const ModelProps& props, int dim,
                                         double R1, double R2, bool ball_facet) {
  return std::visit(
      [&](const auto& p) -> std::uint32_t {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, LinearProps>) {
          b.linear.push_back(LinearContact{linear::make_params(p, dim, R1, R2, ball_facet), {}});
          return static_cast<std::uint32_t>(b.linear.size() - 1);
        }
      },
      props);
}

/// Move the data of one contact from one batch set to another (used when the list is rebuilt).
inline std::uint32_t move_contact_data(ModelBatches& to, ModelBatches& from, ModelKind kind,
                                       std::uint32_t slot) {
  switch (kind) {
  case ModelKind::Linear:
    to.linear.push_back(from.linear[slot]);
    return static_cast<std::uint32_t>(to.linear.size() - 1);
  }
  __builtin_unreachable();
}

} // namespace rocklab
