// A material property a test measures, declared once by that test with everything generic code
// needs to show and use it: its label and kind (so its unit), whether the suite headlines it, how
// it is measured, what its line says beside the value or in its place, and its role in a
// calibration's stages. The suite table, summary.csv, summary.json's methods and the calibration's
// targets are built from these declarations (lab/suite.cpp, lab/calibration/); no generic code
// names a test or a property. Units SI; printed in MPa, GPa and degrees.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace rocklab {

/// What a property's number is, and so how it prints.
enum class PropertyKind {
  Stress,  ///< Pa, printed in MPa; a calibration takes a stress target relative to the strength
  Modulus, ///< Pa, printed in GPa
  Ratio,   ///< dimensionless
  Angle,   ///< degrees
  Count,   ///< a number of tests, points, ...
};

/// The part a property plays in a calibration's stages (docs/calibration.md, "Why three stages").
enum class CalibrationRole {
  Reported,       ///< steered by stage 3 where it is a target and scale-free, otherwise reported
  Modulus,        ///< stage 1 scales the moduli by target / measured (Young's modulus)
  StiffnessRatio, ///< stage 1 searches the stiffness ratios for it (Poisson's ratio)
  Strength,       ///< stage 2 scales the strengths by target / measured (the UCS); stage 3 takes
                  ///< the other stress targets relative to it
};

/// A property a test gives suites and calibrations. Designated initializers keep the declarations
/// readable: {.name = "ucs_Pa", .label = "UCS", .kind = PropertyKind::Stress, ...}.
struct SuiteProperty {
  const char* name;            ///< key in summary.json and as a calibration target
  const char* label = nullptr; ///< as tables print it (nullptr: the name)
  PropertyKind kind = PropertyKind::Ratio;
  int headline = 0; ///< place in the suite's headline (1 first); 0: after them
  CalibrationRole role = CalibrationRole::Reported;
  const char* method = nullptr; ///< how it is measured (summary.json "methods"), or nullptr
  /// Printed after the value, with {key} or {key:MPa} replaced by summary keys (nullptr: none).
  const char* detail = nullptr;
  /// Printed when no value was measured, "LABEL not measured (...)", where every {key} in it has
  /// a value (nullptr, or a key without one: "LABEL -").
  const char* missing = nullptr;
  /// The share of valid tests this property rests on (a summary key; nullptr: every test counts):
  /// a calibration leaves the property out of a seed whose share is 0.
  const char* valid_share = nullptr;
  /// For a share of valid tests (0-1): the summary key counting the tests it is a share of.
  const char* share_of = nullptr;
  int count = 1;               ///< tests of the declaring kind it needs
  const char* other = nullptr; ///< a second kind of test it needs as well, or nullptr
};

/// Every property the frame tests declare, in the protocol table's order, each with the test type
/// that declares it (the first, where two declare one).
struct DeclaredProperty {
  SuiteProperty p;
  std::string test;
};
const std::vector<DeclaredProperty>& declared_properties();
/// Every results.json key the frame tests declare as a per-test column (result_columns), alike.
const std::vector<DeclaredProperty>& declared_result_columns();
/// The declaration of `name`, nullptr when no test declares it.
const SuiteProperty* find_property(const std::string& name);

/// The role and kind `name` is declared with (an undeclared name: a reported ratio).
CalibrationRole property_role(const std::string& name);
PropertyKind property_kind(const std::string& name);

/// How the declared shares of valid tests judge validity (their method texts, "; "-joined): what
/// a calibration says of the tests it left out.
std::string validity_rules();

/// The unit a kind prints in ("MPa", "GPa", "deg" or "") and the factor from SI to it.
const char* display_unit(PropertyKind k);
double display_scale(PropertyKind k);
/// A value as tables print it: "%.4g" in the kind's unit, with the unit ("69.9 GPa"); "-" when it
/// is not a number.
std::string format_property(const nlohmann::json& v, PropertyKind k);
/// `text` with every {key} or {key:UNIT} (UNIT: MPa, GPa, deg) replaced by props[key] as tables
/// print it; `complete` (when given) false where a key has no number.
std::string fill_template(const std::string& text, const nlohmann::json& props,
                          bool* complete = nullptr);
/// "LABEL VALUE [detail]", or "LABEL not measured (missing)" / "LABEL -" without a value.
std::string property_text(const SuiteProperty& p, const nlohmann::json& props);

} // namespace rocklab
