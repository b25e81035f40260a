// What a test in the loading frame shows: its snapshots for ParaView and the plots (grains with
// their stresses, the specimen's outline for the faced cells) and the fracture picture (one crack
// per broken contact, fracture events). Units SI.
#pragma once

#include "lab/fractures.hpp"
#include "lab/frame/loading_frame.hpp"
#include "lab/protocol.hpp"
#include "viz/vtk_output.hpp"

#include <nlohmann/json.hpp>

namespace rocklab {

/// The specimen's outline now, which the grains' power cells fill: along the axis the actuators'
/// separation about the grains' middle, across it the current section (round: a circle of the
/// current area; else the initial widths scaled to it); a diametral disk keeps its first outline.
ClipShape specimen_outline(const LoadingFrame& f);

/// What the frame shows at one moment, with every crack so far.
Snapshot frame_snapshot(const LoadingFrame& f);

/// One crack per broken contact and the fracture events as of `until`.
void add_fractures(Snapshot& s, const std::vector<Crack>& cracks, const EventClustering& ev,
                   double until);

/// The fracture events of the test: cracks clustered with the protocol's window, or by default
/// the time a P wave (sqrt(E / rho), the test's E, the grains' density) takes to cross five mean
/// grain diameters. The results get a summary.
EventClustering fracture_events(const LoadingFrame& f, const Protocol& p, nlohmann::json& r);

} // namespace rocklab
