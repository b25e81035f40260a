#include "viz/svg_png.hpp"

#include "io/output_dir.hpp"

#include <cairo.h>
#include <librsvg/rsvg.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace rocklab {

namespace {

struct GFree {
  void operator()(RsvgHandle* h) const { g_object_unref(h); }
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};

} // namespace

void write_png_of_svg(const std::string& svg, const std::filesystem::path& png, double scale) {
  GError* err = nullptr;
  std::unique_ptr<RsvgHandle, GFree> h(
      rsvg_handle_new_from_data(reinterpret_cast<const guint8*>(svg.data()), svg.size(), &err));
  if (!h) {
    const std::string why = err ? err->message : "unknown error";
    if (err)
      g_error_free(err);
    throw std::runtime_error(png.string() + ": cannot read the SVG to render: " + why);
  }
  gdouble w = 0, hgt = 0;
  if (!rsvg_handle_get_intrinsic_size_in_pixels(h.get(), &w, &hgt) || !(w > 0) || !(hgt > 0))
    throw std::runtime_error(png.string() + ": the SVG has no size in pixels");
  const int pw = static_cast<int>(std::ceil(w * scale)),
            ph = static_cast<int>(std::ceil(hgt * scale));
  std::unique_ptr<cairo_surface_t, GFree> surf(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, pw, ph));
  std::unique_ptr<cairo_t, GFree> cr(cairo_create(surf.get()));
  cairo_set_source_rgb(cr.get(), 1, 1, 1);
  cairo_paint(cr.get());
  const RsvgRectangle viewport{0, 0, static_cast<double>(pw), static_cast<double>(ph)};
  if (!rsvg_handle_render_document(h.get(), cr.get(), &viewport, &err)) {
    const std::string why = err ? err->message : "unknown error";
    if (err)
      g_error_free(err);
    throw std::runtime_error(png.string() + ": cannot render the SVG: " + why);
  }
  cairo_surface_flush(surf.get());
  if (cairo_surface_write_to_png(surf.get(), png.c_str()) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(png.string() + ": cannot write the PNG");
}

std::pair<std::string, std::string> write_svg_and_png(const std::filesystem::path& svg_path,
                                                      const std::string& svg) {
  write_text_file(svg_path, svg);
  std::filesystem::path png = svg_path;
  png.replace_extension(".png");
  write_png_of_svg(svg, png);
  return {svg_path.filename().string(), png.filename().string()};
}

std::pair<int, int> png_size(const std::filesystem::path& png) {
  std::ifstream in(png, std::ios::binary);
  unsigned char b[24] = {};
  if (!in.read(reinterpret_cast<char*>(b), 24) || b[1] != 'P' || b[2] != 'N' || b[3] != 'G')
    return {0, 0};
  auto be = [&](int o) { return (b[o] << 24) | (b[o + 1] << 16) | (b[o + 2] << 8) | b[o + 3]; };
  return {be(16), be(20)};
}

} // namespace rocklab
