#include "lab/protocol_table.hpp"

#include "io/json_input.hpp"
#include "lab/frame/frame_test.hpp"

namespace rocklab {

// Each test's factory, defined in lab/protocols/NAME.cpp.
std::unique_ptr<LabProtocol> make_ucs_test();
std::unique_ptr<LabProtocol> make_triaxial_test();
std::unique_ptr<LabProtocol> make_brazilian_test();
std::unique_ptr<LabProtocol> make_direct_tension_test();
std::unique_ptr<LabProtocol> make_drop_test();

namespace {

struct Row {
  const char* name;                       ///< the protocol's "test"
  std::unique_ptr<LabProtocol> (*make)(); ///< a fresh instance for one run
};

// The table: one row per test.
const Row kTests[] = {
    {"ucs", make_ucs_test},
    {"triaxial", make_triaxial_test},
    {"brazilian", make_brazilian_test},
    {"direct_tension", make_direct_tension_test},
    {"drop", make_drop_test},
};

// Tests registered from outside this table (a test fixture), after the table's.
std::vector<Row>& registered() {
  static std::vector<Row> rows;
  return rows;
}

std::vector<Row> all_rows() {
  std::vector<Row> rows(std::begin(kTests), std::end(kTests));
  rows.insert(rows.end(), registered().begin(), registered().end());
  return rows;
}

} // namespace

bool register_lab_protocol(const char* name, std::unique_ptr<LabProtocol> (*make)()) {
  for (const Row& r : all_rows())
    if (std::string_view(name) == r.name)
      return false;
  registered().push_back({name, make});
  return true;
}

std::vector<std::string> lab_protocol_names() {
  std::vector<std::string> names;
  for (const Row& r : all_rows())
    names.emplace_back(r.name);
  return names;
}

std::vector<std::string> frame_test_names() {
  std::vector<std::string> names;
  for (const Row& r : all_rows())
    if (dynamic_cast<FrameTest*>(r.make().get()))
      names.emplace_back(r.name);
  return names;
}

std::unique_ptr<LabProtocol> make_lab_protocol(std::string_view name) {
  for (const Row& r : all_rows())
    if (name == r.name)
      return r.make();
  return nullptr;
}

std::unique_ptr<FrameTest> make_frame_test(std::string_view name) {
  std::unique_ptr<LabProtocol> p = make_lab_protocol(name);
  if (auto* f = dynamic_cast<FrameTest*>(p.get())) {
    p.release();
    return std::unique_ptr<FrameTest>(f);
  }
  return nullptr;
}

std::unique_ptr<LabProtocol> lab_protocol_of(const nlohmann::json& j, const std::string& file) {
  JsonObject top(j, file, "");
  return make_lab_protocol(top.choice("test", lab_protocol_names()));
}

} // namespace rocklab
