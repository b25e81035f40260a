// libFuzzer target for rocklab's input loaders (opt-in: -DROCKLAB_FUZZ=ON with clang, see
// tests/fuzz/README.md). The first byte picks the loader — scene, material card, protocol, suite,
// calibration file or specimen/checkpoint file — and the rest is the file's bytes. A loader may
// accept the input or reject it with InputError; any other exception, a crash, a leak or undefined
// behaviour (the target is built with ASan and UBSan) is a finding.
#include "io/input_error.hpp"
#include "io/scene.hpp"
#include "io/specimen.hpp"
#include "lab/calibration/calibration_file.hpp"
#include "lab/protocol.hpp"
#include "lab/suite.hpp"
#include "materials/material_card.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1)
    return 0;
  static const std::string path = "/tmp/rocklab-fuzz-" + std::to_string(::getpid()) + ".json";
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    switch (data[0] % 6) {
    case 0:
      rocklab::load_scene(path);
      break;
    case 1:
      rocklab::load_material_card(path);
      break;
    case 2:
      rocklab::load_protocol(path);
      break;
    case 3:
      rocklab::load_suite(path);
      break;
    case 4:
      rocklab::calibration::load_calibration(path);
      break;
    default:
      rocklab::load_model(path);
    }
  } catch (const rocklab::InputError&) {
    // the documented outcome of bad input (exit 2)
  } catch (const std::exception& e) {
    std::fprintf(stderr, "loader %d threw a non-input error: %s\n", data[0] % 6, e.what());
    std::abort();
  }
  return 0;
}
