// The error every input check throws: it names the file, the key, the value and the allowed range.
// Kept apart from the JSON reader so that code which only validates (archives, contact models)
// need not pull in the JSON library.
#pragma once

#include <stdexcept>
#include <string>

namespace rocklab {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Runs load() (which reads a file another input file named) and, when it fails on its input, says
// which file and key named it: "PROTOCOL: key 'specimen.file': SPECIMEN: ...".
template <class Load> auto named_by(const std::string& file, const std::string& key, Load&& load) {
  try {
    return load();
  } catch (const InputError& e) {
    throw InputError(file + ": key '" + key + "': " + e.what());
  }
}

} // namespace rocklab
