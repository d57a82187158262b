#pragma once
// the scenario's keys: each one's section, name, unit, range and where it
// lands in the Scenario struct. One table (scenario.cc) drives reading,
// validation and writing back.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "sim/runner/ini.h"

namespace paddock::runner {

struct Scenario;

struct Field {
  std::string section;
  std::string key;
  std::string unit;  // SI unit of the stored value ("" for none)
  std::string doc;
  bool required = false;  // no default: must be given (the [vehicle] keys)
  // parses e.value into the scenario; throws UserError "file:line: ..."
  std::function<void(Scenario&, const IniEntry& e)> set;
  // the stored value as INI text ("" when an optional value is unset)
  std::function<std::string(const Scenario&)> get;
};

// a number with an optional unit after it ("25 deg", "90 km/h", "0.5"); a bare
// number is in `unit`; other units convert when they measure the same thing;
// the result must lie in [lo, hi]; throws UserError "file:line: ..."
double parse_quantity(const IniEntry& e, const std::string& unit, double lo, double hi);
long parse_integer(const IniEntry& e, long lo, long hi);
bool parse_bool(const IniEntry& e);

// every key of the scenario, in the order the resolved file lists them
const std::vector<Field>& scenario_fields();

}  // namespace paddock::runner
