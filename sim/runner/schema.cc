#include "sim/runner/schema.h"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <optional>
#include <type_traits>

#include "sim/runner/files.h"
#include "sim/runner/scenario.h"

namespace paddock::runner {
namespace {

// other units accepted for a stored SI unit, with their factor to it
const std::map<std::string, std::map<std::string, double>>& conversions() {
  static const std::map<std::string, std::map<std::string, double>> table = {
      {"rad", {{"deg", kPi / 180.0}}},
      {"rad/s", {{"deg/s", kPi / 180.0}}},
      {"m/s", {{"km/h", 1.0 / 3.6}}},
      {"s", {{"ms", 1e-3}}},
      {"m", {{"cm", 1e-2}, {"mm", 1e-3}}},
      {"m/s^2", {{"g", kGravity}}},
  };
  return table;
}

std::string what(const IniEntry& e) { return "[" + e.section + "] " + e.key; }

// integer fields: int, long, the seed
template <class T>
constexpr bool is_integer_v = std::is_integral_v<T> && !std::is_same_v<T, bool>;

// a number field's text: integers as integers, reals as the shortest text
// that reads back to the same double
template <class T>
std::string text_of(const T& v) {
  if constexpr (is_integer_v<T>) return std::to_string(v);
  else return params::number(v);
}

template <class T>
T parse_number(const IniEntry& e, const params::Spec& spec) {
  if constexpr (is_integer_v<T>) return static_cast<T>(parse_integer(e, spec.bounds));
  else return static_cast<T>(parse_quantity(e, spec.unit, spec.bounds));
}

// the visitor that binds every field of a Scenario to a Key
class KeyCollector {
 public:
  std::vector<Key> keys;
  std::vector<SectionDoc> sections;

  template <class T>
  void operator()(const char* name, T& field, const params::Spec& spec) {
    Key k = key(name, spec.unit, params::bounds_text(spec.bounds, spec.unit), spec.doc);
    k.bounds = spec.bounds;
    T* f = &field;
    if constexpr (params::detail::is_optional<T>::value) {
      using V = typename T::value_type;
      k.integer = is_integer_v<V>;
      k.set = [f, spec](const IniEntry& e) { *f = parse_number<V>(e, spec); };
      k.get = [f] { return *f ? text_of(**f) : std::string(); };
    } else {
      // a real without a default in code must be given (the vehicle's keys)
      if constexpr (std::is_floating_point_v<T>) k.required = std::isnan(field);
      k.integer = is_integer_v<T>;
      k.set = [f, spec](const IniEntry& e) { *f = parse_number<T>(e, spec); };
      k.get = [f] { return text_of(*f); };
    }
    keys.push_back(std::move(k));
  }

  // a list: numbers separated by commas, each in the bounds
  template <class T>
  void operator()(const char* name, std::vector<T>& field, const params::Spec& spec) {
    Key k = key(name, spec.unit, "numbers separated by commas, each " + params::bounds_text(spec.bounds, spec.unit), spec.doc);
    k.bounds = spec.bounds;
    k.list = true;
    std::vector<T>* f = &field;
    k.set = [f, spec](const IniEntry& e) {
      std::vector<T> items;
      std::string rest = e.value;
      for (;;) {
        const auto comma = rest.find(',');
        IniEntry item = e;
        item.value = trim(rest.substr(0, comma));
        items.push_back(parse_number<T>(item, spec));
        if (comma == std::string::npos) break;
        rest = rest.substr(comma + 1);
      }
      *f = std::move(items);
    };
    k.get = [f] {
      std::string text;
      for (const T& v : *f) text += (text.empty() ? "" : ", ") + text_of(v);
      return text;
    };
    keys.push_back(std::move(k));
  }

  template <class E, std::size_t N>
  void operator()(const char* name, E& field, const params::Choice<E> (&choices)[N], const char* doc) {
    std::string names;
    for (const params::Choice<E>& c : choices) names += (names.empty() ? "" : ", ") + std::string(c.name);
    Key k = key(name, "", "one of: " + names, doc);
    E* f = &field;
    const params::Choice<E>* table = choices;
    k.set = [f, table, names](const IniEntry& e) {
      for (std::size_t i = 0; i < N; ++i) {
        if (e.value == table[i].name) {
          *f = table[i].value;
          return;
        }
      }
      throw UserError(e.where() + ": " + what(e) + " = '" + e.value + "' is not known; expected one of: " + names);
    };
    k.get = [f, table] {
      for (std::size_t i = 0; i < N; ++i)
        if (table[i].value == *f) return std::string(table[i].name);
      return std::string("?");
    };
    keys.push_back(std::move(k));
  }

  void operator()(const char* name, bool& field, const char* doc) {
    Key k = key(name, "", "true or false", doc);
    bool* f = &field;
    k.set = [f](const IniEntry& e) { *f = parse_bool(e); };
    k.get = [f] { return std::string(*f ? "true" : "false"); };
    keys.push_back(std::move(k));
  }

  void operator()(const char* name, std::optional<bool>& field, const char* doc) {
    Key k = key(name, "", "true or false", doc);
    std::optional<bool>* f = &field;
    k.set = [f](const IniEntry& e) { *f = parse_bool(e); };
    k.get = [f] { return *f ? std::string(**f ? "true" : "false") : std::string(); };
    keys.push_back(std::move(k));
  }

  void operator()(const char* name, std::string& field, const char* doc) {
    Key k = key(name, "", "text", doc);
    std::string* f = &field;
    k.set = [f](const IniEntry& e) { *f = e.value; };
    k.get = [f] { return *f; };
    keys.push_back(std::move(k));
  }

  template <class P>
  void section(const char* name, P& sub, const char* doc) {
    const std::string outer = section_;
    section_ = outer.empty() ? name : outer + "." + name;
    sections.push_back({section_, doc});
    sub.visit(*this);
    section_ = outer;
  }

 private:
  Key key(const char* name, const std::string& unit, const std::string& expected, const char* doc) const {
    Key k;
    k.section = section_;
    k.name = name;
    k.unit = unit;
    k.expected = expected;
    k.doc = doc;
    return k;
  }

  std::string section_;
};

}  // namespace

std::vector<Key> scenario_keys(Scenario& s) {
  KeyCollector c;
  s.visit(c);
  return std::move(c.keys);
}

std::vector<Key> profile_keys(planning::VelocityProfileParams& p) {
  KeyCollector c;
  p.visit(c);
  return std::move(c.keys);
}

std::vector<SectionDoc> scenario_sections() {
  Scenario s;
  KeyCollector c;
  s.visit(c);
  return std::move(c.sections);
}

std::string keys_markdown() {
  Scenario defaults;
  const std::vector<Key> keys = scenario_keys(defaults);
  std::string out = "| key | default | unit | value | meaning |\n|---|---|---|---|---|\n";
  for (const SectionDoc& section : scenario_sections()) {
    out += "| **[" + section.section + "]** | | | | " + section.doc + " |\n";
    for (const Key& k : keys) {
      if (k.section != section.section) continue;
      const std::string value = k.required ? "required" : k.get();
      out += "| `" + k.name + "` | " + (value.empty() ? "unset" : "`" + value + "`") + " | " + k.unit + " | " +
             k.expected + " | " + k.doc + " |\n";
    }
  }
  return out;
}

double parse_quantity(const IniEntry& e, const std::string& unit, const params::Bounds& bounds) {
  const std::string& v = e.value;
  const char* begin = v.c_str();
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(begin, &end);
  const std::string expected = "expected a number" + (unit.empty() ? std::string() : " in " + unit);
  if (end == begin || errno == ERANGE || !std::isfinite(x)) {
    throw UserError(e.where() + ": " + what(e) + " = '" + v + "' is not a number; " + expected);
  }
  const std::string suffix = trim(std::string(end));
  double factor = 1.0;
  if (!suffix.empty() && suffix != unit) {
    const auto table = conversions().find(unit);
    const auto conv = table == conversions().end() ? nullptr : &table->second;
    if (!conv || conv->find(suffix) == conv->end()) {
      throw UserError(e.where() + ": " + what(e) + " = '" + v + "': unit '" + suffix + "' does not fit; " + expected);
    }
    factor = conv->at(suffix);
  }
  const double value = x * factor;
  if (!bounds.contains(value)) {
    throw UserError(e.where() + ": " + what(e) + " = " + v + " is out of range; expected " +
                    params::bounds_text(bounds, unit.c_str()));
  }
  return value;
}

long parse_integer(const IniEntry& e, const params::Bounds& bounds) {
  const char* begin = e.value.c_str();
  char* end = nullptr;
  errno = 0;
  const long x = std::strtol(begin, &end, 10);
  if (end == begin || *end != '\0' || errno == ERANGE) {
    throw UserError(e.where() + ": " + what(e) + " = '" + e.value + "' is not an integer; expected a whole number");
  }
  if (!bounds.contains(static_cast<double>(x))) {
    throw UserError(e.where() + ": " + what(e) + " = " + e.value + " is out of range; expected " +
                    params::bounds_text(bounds, ""));
  }
  return x;
}

bool parse_bool(const IniEntry& e) {
  if (e.value == "true" || e.value == "yes" || e.value == "on" || e.value == "1") return true;
  if (e.value == "false" || e.value == "no" || e.value == "off" || e.value == "0") return false;
  throw UserError(e.where() + ": " + what(e) + " = '" + e.value + "' is not a boolean; expected true or false");
}

}  // namespace paddock::runner
