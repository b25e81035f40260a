// What every SVG writer here needs: numbers with two decimals (pixels) and text escaped for XML.
#pragma once

#include <cstdio>
#include <string>

namespace rocklab::svg {

inline std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

inline std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<')
      o += "&lt;";
    else if (c == '>')
      o += "&gt;";
    else if (c == '&')
      o += "&amp;";
    else
      o += c;
  }
  return o;
}

} // namespace rocklab::svg
