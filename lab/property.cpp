#include "lab/property.hpp"

#include "lab/frame/frame_test.hpp"
#include "lab/protocol_table.hpp"

#include <algorithm>
#include <cstdio>

namespace rocklab {

namespace {

// Every entry a frame test declares through `list`, in the protocol table's order, each name once
// (with the first test that declares it).
std::vector<DeclaredProperty> gather(std::vector<SuiteProperty> (FrameTest::*list)() const) {
  std::vector<DeclaredProperty> out;
  for (const std::string& test : frame_test_names())
    for (const SuiteProperty& p : (*make_frame_test(test).*list)()) // literals: outlive the test
      if (std::none_of(out.begin(), out.end(),
                       [&](const DeclaredProperty& d) { return std::string(d.p.name) == p.name; }))
        out.push_back({p, test});
  return out;
}

} // namespace

const std::vector<DeclaredProperty>& declared_properties() {
  static const std::vector<DeclaredProperty> all = gather(&FrameTest::suite_properties);
  return all;
}

const std::vector<DeclaredProperty>& declared_result_columns() {
  static const std::vector<DeclaredProperty> all = gather(&FrameTest::result_columns);
  return all;
}

const SuiteProperty* find_property(const std::string& name) {
  for (const DeclaredProperty& d : declared_properties())
    if (name == d.p.name)
      return &d.p;
  return nullptr;
}

CalibrationRole property_role(const std::string& name) {
  const SuiteProperty* d = find_property(name);
  return d ? d->role : CalibrationRole::Reported;
}

PropertyKind property_kind(const std::string& name) {
  const SuiteProperty* d = find_property(name);
  return d ? d->kind : PropertyKind::Ratio;
}

std::string validity_rules() {
  std::string out;
  for (const DeclaredProperty& d : declared_properties())
    if (d.p.share_of && d.p.method)
      out += (out.empty() ? "" : "; ") + std::string(d.p.method);
  return out;
}

const char* display_unit(PropertyKind k) {
  switch (k) {
  case PropertyKind::Stress:
    return "MPa";
  case PropertyKind::Modulus:
    return "GPa";
  case PropertyKind::Angle:
    return "deg";
  default:
    return "";
  }
}

double display_scale(PropertyKind k) {
  return k == PropertyKind::Stress ? 1e-6 : k == PropertyKind::Modulus ? 1e-9 : 1.0;
}

namespace {

std::string number_text(const nlohmann::json& v, double scale, const char* unit) {
  if (!v.is_number())
    return "-";
  char b[48];
  std::snprintf(b, sizeof b, "%.4g%s%s", v.get<double>() * scale, *unit ? " " : "", unit);
  return b;
}

} // namespace

std::string format_property(const nlohmann::json& v, PropertyKind k) {
  return number_text(v, display_scale(k), display_unit(k));
}

std::string fill_template(const std::string& text, const nlohmann::json& props, bool* complete) {
  std::string out;
  std::size_t a = 0;
  if (complete)
    *complete = true;
  while (a < text.size()) {
    const std::size_t open = text.find('{', a), close = text.find('}', open);
    if (open == std::string::npos || close == std::string::npos) {
      out += text.substr(a);
      break;
    }
    out += text.substr(a, open - a);
    const std::string field = text.substr(open + 1, close - open - 1);
    const std::size_t colon = field.find(':');
    const std::string key = field.substr(0, colon);
    const std::string unit = colon == std::string::npos ? "" : field.substr(colon + 1);
    const nlohmann::json v = props.value(key, nlohmann::json());
    const double scale = unit == "MPa" ? 1e-6 : unit == "GPa" ? 1e-9 : 1.0;
    out += number_text(v, scale, unit.c_str());
    if (complete && !v.is_number())
      *complete = false;
    a = close + 1;
  }
  return out;
}

std::string property_text(const SuiteProperty& p, const nlohmann::json& props) {
  const std::string label = p.label ? p.label : p.name;
  const nlohmann::json v = props.value(p.name, nlohmann::json());
  if (v.is_number()) {
    std::string s = label + " " + format_property(v, p.kind);
    if (p.detail)
      s += " " + fill_template(p.detail, props);
    return s;
  }
  bool complete = false;
  const std::string why = p.missing ? fill_template(p.missing, props, &complete) : "";
  return complete ? label + " not measured (" + why + ")" : label + " -";
}

} // namespace rocklab
