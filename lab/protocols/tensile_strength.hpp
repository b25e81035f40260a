// The printout line of a tensile strength, shared by the Brazilian and the direct tension test.
// Units SI; printed in MPa and N.
#pragma once

#include "io/results.hpp"

#include <cstdio>
#include <string>

namespace rocklab {

/// "tensile strength X MPa (force F N)", then `more`.
inline void print_tensile_strength(const nlohmann::json& r, const std::string& more = "") {
  std::printf("tensile strength %.4g MPa (force %.4g N)%s\n",
              1e-6 * json_number(r, "tensile_strength_Pa", 0.0),
              json_number(r, "peak_force_N", 0.0), more.c_str());
}

} // namespace rocklab
