// Scenes: hand-built models described in JSON (docs/scene-format.md). Units are SI.
#pragma once

#include "core/model.hpp"
#include "io/json_input.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace rocklab {

/// When a scene run stops.
struct RunSpec {
  std::int64_t cycles = 0;       ///< run exactly this many cycles (0: not used)
  double time = 0;               ///< run until model time reaches this [s] (0: not used)
  double ratio = 0;              ///< stop when the mean unbalanced-force ratio falls below [-]
  std::int64_t max_cycles = 0;   ///< upper bound for time/ratio runs (0: none)
  std::int64_t check_every = 10; ///< cycles between ratio checks
};

/// One history column: a quantity sampled every `every` cycles.
struct HistoryColumn {
  std::string name;
  enum class Kind {
    Step,
    Time,
    Timestep,
    Energy,
    Ball,
    Wall,
    Contacts,
    ActiveContacts,
    Ratio,
    Events,
    Clump,      ///< clump/ID/QUANTITY/COMPONENT
    GroupEnergy ///< group/NAME/PARTITION (thesis section 3 sharing rule)
  };
  Kind kind = Kind::Step;
  std::string quantity;  ///< energy partition, ball/wall quantity or event type
  std::size_t index = 0; ///< ball or wall index
  int component = 0;     ///< 0..2 = x..z, 3 = magnitude
};

/// A change to one ball at the start of a stage.
struct BallChange {
  std::size_t index = 0;
  std::optional<Vec3> velocity, spin;
  std::uint8_t fix = 0;  ///< DOFs to fix
  std::uint8_t free = 0; ///< DOFs to free
};

/// One stage of a run: changes applied at its start, then cycles until its stop rule. Cycle and
/// time limits count from the start of the stage.
/// A contact-model method called at the start of a stage on every contact of one model.
struct MethodCall {
  ModelKind model = model_kind<LinearPBond>;
  std::string method;
  double gap_lo = -1e300, gap_hi = 0;
  bool gap_ratio = false; ///< the gaps are fractions of the contact's radii sum (`gap_ratio`)
  int element = 0;
};

struct Stage {
  RunSpec run;
  std::vector<BallChange> set;
  std::vector<MethodCall> methods;
};

/// Whether results.json lists every contact: `Auto` up to kContactsAutoLimit (results.hpp)
/// contacts (a larger model's list is hundreds of MB), or always / never (`output.contacts`).
enum class ContactOutputMode { Auto, Always, Never };

struct Scene {
  std::string file;
  std::string description;
  std::unique_ptr<Model> model;
  std::vector<Stage> stages;
  std::int64_t history_every = 0;
  std::vector<HistoryColumn> history;
  ContactOutputMode contacts_output = ContactOutputMode::Auto;
};

/// Load and validate a scene file. Throws InputError naming the file, key, value and range.
Scene load_scene(const std::string& path);

/// Event counts accumulated by a run, by type.
struct EventCounts {
  std::int64_t created = 0, deleted = 0, slip_change = 0, bond_break = 0;
  void add(const std::vector<Event>& events);
};

/// Value of one history column in the current state.
/// `groups` is Model::group_energy(), needed only by group columns (may be empty otherwise).
double history_value(const Model& m, const HistoryColumn& c, const EnergyLedger& e,
                     const EventCounts& counts, const std::vector<EnergyLedger>& groups);
/// The pebbles of one clump entry: 'pebbles' (a list of {position, radius}, global) or
/// 'template' + 'radius' (+ 'position' of the pebble centres' centroid, 'rotation': 2D degrees
/// about z, 3D a rotation vector in degrees). Reads only those keys.
std::vector<Pebble> read_clump_pebbles(JsonObject& o, int dim, bool position_required);
/// One energy partition by name (energy/NAME columns): the entries of energy_json (results.hpp);
/// an unknown name throws.
double energy_partition(const EnergyLedger& e, const std::string& name);

} // namespace rocklab
