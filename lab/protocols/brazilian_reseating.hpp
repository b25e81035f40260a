// The Brazilian test's re-seatings: a grain that sticks out of a cut disk can carry the whole
// platen load on one or two bonds; when they break it slides aside and the load collapses without
// a split. The test then has the frame seat the platens again (LoadingFrame::seat_again) and
// keeps here what it judges the reloading by: how often, and since the last seating ended the
// largest load and the platen travel. Read at each of the test's stop checks (every loading step
// past stop.min_steps, which every re-seating follows). Units SI.
#pragma once

#include "lab/frame/loading_frame.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <string>

namespace rocklab {

class PlatenReseating {
public:
  /// Follows the frame at a stop check: a seating that ended at this step starts the reloading.
  void track(const LoadingFrame& f) {
    if (seating_ && !f.seating_again()) {
      reload_peak_ = f.current().load;
      reload_strain0_ = f.current().axial_strain;
    }
    seating_ = f.seating_again();
    reload_peak_ = std::max(reload_peak_, f.current().load);
  }
  /// Asks the frame to seat the platens again; counts it when it does.
  void reseat(LoadingFrame& f) {
    if (f.seat_again())
      ++count_;
  }
  int count() const { return count_; }
  /// Since the last re-seating ended: the largest load [Pa] and the axial strain travelled [-].
  double reload_peak() const { return reload_peak_; }
  double reload_strain(const LoadingFrame& f) const {
    return f.current().axial_strain - reload_strain0_;
  }
  void save(nlohmann::json& state) const {
    state["reseating"] = {count_, seating_, reload_peak_, reload_strain0_};
  }
  /// Throws on a malformed entry (the caller names the checkpoint).
  void load(const nlohmann::json& state) {
    const nlohmann::json& x = state.at("reseating");
    count_ = x.at(0).get<int>();
    seating_ = x.at(1).get<bool>();
    reload_peak_ = x.at(2).get<double>();
    reload_strain0_ = x.at(3).get<double>();
  }

private:
  int count_ = 0;             ///< re-seatings so far
  bool seating_ = false;      ///< the frame was seating again at the last check
  double reload_peak_ = 0;    ///< largest load since the last re-seating ended [Pa]
  double reload_strain0_ = 0; ///< axial strain when the last re-seating ended [-]
};

} // namespace rocklab
