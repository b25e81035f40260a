// The error every input check throws: it names the file, the key, the value and the allowed range.
// Kept apart from the JSON reader so that code which only validates (archives, contact models)
// need not pull in the JSON library.
#pragma once

#include <stdexcept>

namespace rocklab {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

} // namespace rocklab
