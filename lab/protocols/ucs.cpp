// Uniaxial compression (UCS): lubricated platens close on an unconfined cylinder or prism (2D: a
// rectangle) at a constant rate after seating; E and nu from the pre-peak curve, the UCS at the
// peak (docs/protocol-format.md).
#include "lab/protocols/compression.hpp"

namespace rocklab {

namespace {

class UcsTest final : public CompressionTest {
public:
  const char* name() const override { return "ucs"; }
  FrameSetup setup() const override { return {}; }
};

} // namespace

std::unique_ptr<LabProtocol> make_ucs_test() {
  return std::make_unique<UcsTest>();
}

} // namespace rocklab
