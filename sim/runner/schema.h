#pragma once
// the scenario's keys, generated from the Params structs' own declarations
// (autonomy/common/params.h): Scenario::visit names its sections, each
// Params struct its fields. A key's section is the struct path
// ("perception.lidar.clustering"), its name the field's ("tolerance"); its
// unit, bounds and meaning are the field's declaration. The loader, --set,
// the resolved scenario.ini, validation and `paddock keys` (the README's
// table) all read this one list.
#include <functional>
#include <string>
#include <vector>

#include "autonomy/common/params.h"
#include "sim/runner/ini.h"

namespace paddock::planning {
struct VelocityProfileParams;
}

namespace paddock::runner {

struct Scenario;

// one key of one Scenario, bound to its field
struct Key {
  std::string section;  // the struct path, e.g. "perception.lidar.clustering"
  std::string name;     // the field, e.g. "tolerance"
  std::string unit;     // SI unit of the stored value ("" for none)
  std::string expected;  // what a value must be: "> 0 m", "one of: a, b", "true or false", ...
  std::string doc;
  bool required = false;  // no default in code (a NaN: the [vehicle] keys)
  params::Bounds bounds;  // a number's bounds (any for other kinds)
  bool integer = false;   // a whole number
  bool list = false;      // numbers separated by commas
  // parses e.value into the field; throws UserError "file:line: ..."
  std::function<void(const IniEntry& e)> set;
  // the field's value as INI text ("" when an optional value is unset)
  std::function<std::string()> get;

  std::string path() const { return section + "." + name; }
};

// a section's meaning, from the declaration of the struct it is
struct SectionDoc {
  std::string section;
  std::string doc;
};

// every key of s, bound to s's fields, in declaration order; s must outlive them
std::vector<Key> scenario_keys(Scenario& s);
// the same for a velocity profile's own keys (section ""): the car's measured
// envelope kept between runs (limit_report.cc)
std::vector<Key> profile_keys(planning::VelocityProfileParams& p);
// every section (with its meaning), in declaration order
std::vector<SectionDoc> scenario_sections();

// the README's table of every section and key (Markdown): section, key,
// default, unit, what a value must be, meaning; `paddock keys` prints it
std::string keys_markdown();

// a number with an optional unit after it ("25 deg", "90 km/h", "0.5"); a bare
// number is in `unit`; other units convert when they measure the same thing;
// the result must lie in `bounds`; throws UserError "file:line: ..."
double parse_quantity(const IniEntry& e, const std::string& unit, const params::Bounds& bounds);
long parse_integer(const IniEntry& e, const params::Bounds& bounds);
bool parse_bool(const IniEntry& e);

}  // namespace paddock::runner
