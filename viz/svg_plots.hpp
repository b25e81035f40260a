// Pictures a person can open without ParaView (any web browser): line plots and a crack map, as
// SVG. Units are written on the axes.
#pragma once

#include "viz/vtk_output.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace rocklab {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
  std::string color = "#1f77b4";
  bool dashed = false;
  bool right_axis = false; ///< plotted against the right-hand axis
};

struct PlotMarker {
  double x = 0, y = 0;
  std::string label;
};

/// A line plot with up to two y axes. Returns the SVG text. The left axis reaches at least
/// `y_top` when it is finite (room above the data, e.g. for the legend); with `log_y` it is
/// logarithmic (ticks on whole decades; values <= 0 are not drawn, markers there sit on the axis).
/// `whole_x`: the x axis counts something (evaluations): its ticks fall on whole numbers only.
std::string line_plot_svg(const std::string& title, const std::string& xlabel,
                          const std::string& ylabel, const std::string& y2label,
                          const std::vector<PlotSeries>& series,
                          const std::vector<PlotMarker>& markers = {}, double y_top = NAN,
                          bool log_y = false, bool whole_x = false);

/// The cracks of a snapshot over its grains: 2D as it is; 3D a central section seen along
/// `depth_axis` (1: y, x right and z up; 2: z, x right and y up — a Brazilian disk's faces),
/// each crack drawn as its trace. Red: tension, blue: shear. `disk`: a Brazilian disk loaded
/// along the picture's vertical: every crack through its thickness (projected onto the face, over
/// the mid-section's grains), the loaded diameter dashed and the platens' contact points marked.
std::string crack_map_svg(const Snapshot& s, const std::string& title, int depth_axis = 1,
                          bool disk = false);

} // namespace rocklab
