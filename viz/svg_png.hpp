// A PNG beside each SVG plot, for documents and slides that do not take SVG: the SVG text is
// rendered with librsvg onto a cairo image surface (fonts from fontconfig). Units of the plots
// are SI as written on their axes.
#pragma once

#include <filesystem>
#include <string>

namespace rocklab {

/// Render SVG text to a PNG file at `scale` × its own size in pixels. Throws std::runtime_error
/// naming the file when the SVG cannot be parsed or the PNG cannot be written.
void write_png_of_svg(const std::string& svg, const std::filesystem::path& png, double scale = 2);

/// Write `svg` to `svg_path` and its PNG beside it (same name, .png); returns both file names.
std::pair<std::string, std::string> write_svg_and_png(const std::filesystem::path& svg_path,
                                                      const std::string& svg);

/// Width and height in pixels of a PNG file (from its header); {0, 0} if it is not a PNG.
std::pair<int, int> png_size(const std::filesystem::path& png);

} // namespace rocklab
