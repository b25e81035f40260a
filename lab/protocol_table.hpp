// The table of laboratory tests by the name a protocol file gives in "test". Adding a test: its
// file under lab/protocols/ (a FrameTest: set-up, readings, results, printout lines, plot markers
// and the suite properties it measures), one row in protocol_table.cpp (CMake builds every file in
// lab/protocols/), its docs and its test (docs/architecture.md, "Recipe: add a lab protocol").
#pragma once

#include "lab/lab_protocol.hpp"

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace rocklab {

class FrameTest;

/// Adds a test defined outside the table (a test fixture; the shipped tests are the table's rows),
/// after the table's; false where the name is taken. Call before the first lookup: the declared
/// properties and columns are gathered once.
bool register_lab_protocol(const char* name, std::unique_ptr<LabProtocol> (*make)());
/// The names of every test, in table order.
std::vector<std::string> lab_protocol_names();
/// The names of the tests run in the loading frame (protocol files with a specimen; suites).
std::vector<std::string> frame_test_names();
/// A fresh instance of the test named `name` (nullptr if there is none).
std::unique_ptr<LabProtocol> make_lab_protocol(std::string_view name);
/// A fresh instance of the frame test named `name` (nullptr if it is not one).
std::unique_ptr<FrameTest> make_frame_test(std::string_view name);
/// The test a protocol file asks for (its "test" key); a missing or unknown name fails like any
/// bad key (InputError naming the file).
std::unique_ptr<LabProtocol> lab_protocol_of(const nlohmann::json& j, const std::string& file);

} // namespace rocklab
