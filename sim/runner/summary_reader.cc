#include "sim/runner/summary_reader.h"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "sim/runner/files.h"

namespace paddock::runner {
namespace {

using nlohmann::json;

const json& field(const json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw UserError(where + ": no field '" + key + "'");
  return j.at(key);
}

double number(const json& j, const char* key, const std::string& where) {
  const json& v = field(j, key, where);
  if (!v.is_number() || !std::isfinite(v.get<double>())) throw UserError(where + ": '" + key + "' is not a finite number");
  return v.get<double>();
}

int count(const json& j, const char* key, const std::string& where) {
  const json& v = field(j, key, where);
  if (v.is_number_unsigned() && v.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
    return static_cast<int>(v.get<std::uint64_t>());
  if (v.is_number_integer() && !v.is_number_unsigned() && v.get<std::int64_t>() >= 0 &&
      v.get<std::int64_t>() <= std::numeric_limits<int>::max())
    return static_cast<int>(v.get<std::int64_t>());
  throw UserError(where + ": '" + key + "' is not a count (a whole number from 0)");
}

bool flag(const json& j, const char* key, const std::string& where) {
  const json& v = field(j, key, where);
  if (!v.is_boolean()) throw UserError(where + ": '" + key + "' is not true or false");
  return v.get<bool>();
}

}  // namespace

SummaryLaps parse_summary(const std::string& text, const std::string& source) {
  const std::string where = source + ": not a paddock summary";
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded()) throw UserError(where + ": not JSON");
  SummaryLaps s;
  const json& laps = field(j, "laps", where);
  if (!laps.is_array()) throw UserError(where + ": 'laps' is not a list");
  for (const json& lap : laps) {
    s.start.push_back(number(lap, "start", where));
    s.time.push_back(number(lap, "time", where));
    s.timed.push_back(flag(lap, "timed", where));
    s.doo.push_back(count(lap, "doo", where));
    s.oc.push_back(count(lap, "oc", where));
  }
  s.total_time = number(j, "total_time", where);
  s.finished = flag(j, "finished", where);
  const json& name = field(j, "scenario", where);
  if (!name.is_string()) throw UserError(where + ": 'scenario' is not text");
  s.scenario = name.get<std::string>();
  return s;
}

}  // namespace paddock::runner
