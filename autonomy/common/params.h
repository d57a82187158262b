#pragma once
// every parameter declared once, beside its field. Drake's Serialize(Archive*)
// with DRAKE_NVP is the model: a Params struct lists its fields in a member
//
//   template <class V>
//   void visit(V& v) {
//     v(PADDOCK_PARAM(tolerance), {"m", params::above(0.0), "points closer than this join one cluster"});
//     v(PADDOCK_PARAM(min_points), {"", params::at_least(1), "smaller clusters are dropped"});
//     v(PADDOCK_PARAM(bounds), {"m", params::above(0.0), "region edges"});      // a std::vector: each item
//     v(PADDOCK_PARAM(method), kMethodNames, "how the centreline is smoothed");  // an enum
//     v(PADDOCK_PARAM(occlusion), "cones hide the cones behind them");              // a bool (or optional bool)
//     v.section(PADDOCK_PARAM(ground), "the ground segmentation");                  // a nested Params
//   }
//
// and, where a rule ties fields together, a member `std::string check() const`
// returning "" or the problem, starting with the field's name. Everything else
// comes from that list: validate() below (every field's bounds, then check(),
// of the struct and of every nested one), and in the runner the scenario's INI
// keys (the section is the struct path, the key the field's name), --set, the
// resolved scenario.ini and the README's table of keys.
//
// A visit function only hands out references; visitors that read (validate,
// the writers) call it through a const_cast and never write.
//
// Why a visit function and not an X-macro list: the fields stay ordinary
// members with ordinary defaults (aggregate initialisation, designated
// comments, debuggers and IDEs all see plain structs), nested structs and
// enums need no special macro forms, and each visitor is ordinary C++.
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

// the key of a field is its member name
#define PADDOCK_PARAM(member) #member, member

namespace paddock::params {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

// the range a number must lie in, either end open or closed; every number
// must also be finite
struct Bounds {
  double lo = -kInf;
  double hi = kInf;
  bool lo_open = false;
  bool hi_open = false;

  bool contains(double v) const {
    if (!std::isfinite(v)) return false;
    if (lo_open ? !(v > lo) : !(v >= lo)) return false;
    return hi_open ? v < hi : v <= hi;
  }
};

constexpr Bounds any() { return {}; }
constexpr Bounds at_least(double lo) { return {lo, kInf, false, false}; }
constexpr Bounds above(double lo) { return {lo, kInf, true, false}; }
constexpr Bounds at_most(double hi) { return {-kInf, hi, false, false}; }
constexpr Bounds below(double hi) { return {-kInf, hi, false, true}; }
// [lo, hi]
constexpr Bounds in(double lo, double hi) { return {lo, hi, false, false}; }
// (lo, hi]
constexpr Bounds above_up_to(double lo, double hi) { return {lo, hi, true, false}; }
// [lo, hi)
constexpr Bounds from_below(double lo, double hi) { return {lo, hi, false, true}; }
// [0, 1]: a probability, a share, a weight
constexpr Bounds fraction() { return {0.0, 1.0, false, false}; }

// what a number field is: its SI unit ("" for none), its bounds, its meaning
struct Spec {
  const char* unit = "";
  Bounds bounds;
  const char* doc = "";
};

// one value of an enum field and its name in a scenario
template <class E>
struct Choice {
  const char* name;
  E value;
};

// a number as the shortest text that reads back to the same value
std::string number(double v);

// "> 0 m", ">= 1", "in [0, 1]", "in (0, 1.5] rad", "any number"
std::string bounds_text(const Bounds& b, const char* unit);

namespace detail {
template <class P, class = void>
struct has_check : std::false_type {};
template <class P>
struct has_check<P, std::void_t<decltype(std::declval<const P&>().check())>> : std::true_type {};
template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};
}  // namespace detail

// runs p.check() when P has one
template <class P>
std::string check_of(const P& p) {
  if constexpr (detail::has_check<P>::value) return p.check();
  else return "";
}

// what the visitors below share: the path of the section being visited,
// with a trailing '.' ("ground."), kept while a nested struct is visited
class SectionPath {
 protected:
  // sub's fields visited by v under key's path; then after(), still there
  template <class V, class P, class After>
  void descend(V& v, const char* key, P& sub, After after) {
    const std::size_t size = prefix_.size();
    prefix_ += key;
    prefix_ += '.';
    sub.visit(v);
    after();
    prefix_.resize(size);
  }
  template <class V, class P>
  void descend(V& v, const char* key, P& sub) {
    descend(v, key, sub, [] {});
  }
  std::string prefix_;
};

// the first field (depth first, in declaration order) outside its bounds, or
// the first check() that fails; "" when all is well
class Validator : SectionPath {
 public:
  const std::string& problem() const { return problem_; }

  template <class T>
  void operator()(const char* key, T& field, const Spec& spec) {
    if (!problem_.empty()) return;
    if constexpr (detail::is_optional<T>::value) {
      if (field) (*this)(key, *field, spec);
    } else {
      static_assert(std::is_arithmetic_v<T>, "a Spec describes a number");
      const double v = static_cast<double>(field);
      if (!spec.bounds.contains(v))
        problem_ = prefix_ + key + " must be " + bounds_text(spec.bounds, spec.unit) + " (got " + number(v) + ")";
    }
  }
  template <class T>
  void operator()(const char* key, std::vector<T>& list, const Spec& spec) {
    for (std::size_t i = 0; i < list.size() && problem_.empty(); ++i) {
      const std::string item = std::string(key) + "[" + std::to_string(i) + "]";
      (*this)(item.c_str(), list[i], spec);
    }
  }
  template <class E, std::size_t N>
  void operator()(const char* key, E& field, const Choice<E> (&choices)[N], const char*) {
    if (!problem_.empty()) return;
    for (const Choice<E>& c : choices)
      if (c.value == field) return;
    problem_ = prefix_ + key + " has a value that is not one of its names";
  }
  void operator()(const char*, bool&, const char*) {}
  void operator()(const char*, std::optional<bool>&, const char*) {}
  void operator()(const char*, std::string&, const char*) {}

  template <class P>
  void section(const char* key, P& sub, const char*) {
    if (!problem_.empty()) return;
    descend(*this, key, sub, [&] {
      if (!problem_.empty()) return;
      const std::string why = check_of(sub);
      if (!why.empty()) problem_ = prefix_ + why;
    });
  }

 private:
  std::string problem_;
};

// the path of every field of p (and of the structs nested in it), in
// declaration order: "tolerance", "ground.max_slope", ...
class PathLister : SectionPath {
 public:
  std::vector<std::string> paths;

  template <class T>
  void operator()(const char* key, T&, const Spec&) { add(key); }
  template <class E, std::size_t N>
  void operator()(const char* key, E&, const Choice<E> (&)[N], const char*) { add(key); }
  void operator()(const char* key, bool&, const char*) { add(key); }
  void operator()(const char* key, std::optional<bool>&, const char*) { add(key); }
  void operator()(const char* key, std::string&, const char*) { add(key); }
  template <class P>
  void section(const char* key, P& sub, const char*) {
    descend(*this, key, sub);
  }

 private:
  void add(const char* key) { paths.push_back(prefix_ + key); }
};

template <class P>
std::vector<std::string> field_paths(const P& p) {
  PathLister l;
  const_cast<P&>(p).visit(l);  // reads only
  return l.paths;
}

// every field of p (and of the structs nested in it) as "path=value" lines,
// numbers exactly (number(): the shortest text that reads back the same):
// two structs with the same text hold the same values (a cache key)
class Fingerprinter : SectionPath {
 public:
  std::string text;

  template <class T>
  void operator()(const char* key, T& field, const Spec&) {
    if constexpr (detail::is_optional<T>::value) {
      add(key, field ? number(static_cast<double>(*field)) : std::string("unset"));
    } else {
      add(key, number(static_cast<double>(field)));
    }
  }
  template <class T>
  void operator()(const char* key, std::vector<T>& list, const Spec& spec) {
    add(key, "list of " + std::to_string(list.size()));
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string item = std::string(key) + "[" + std::to_string(i) + "]";
      (*this)(item.c_str(), list[i], spec);
    }
  }
  template <class E, std::size_t N>
  void operator()(const char* key, E& field, const Choice<E> (&)[N], const char*) {
    add(key, std::to_string(static_cast<long long>(field)));
  }
  void operator()(const char* key, bool& b, const char*) { add(key, b ? "true" : "false"); }
  void operator()(const char* key, std::optional<bool>& b, const char*) { add(key, b ? (*b ? "true" : "false") : "unset"); }
  void operator()(const char* key, std::string& s, const char*) { add(key, std::to_string(s.size()) + ":" + s); }
  template <class P>
  void section(const char* key, P& sub, const char*) {
    descend(*this, key, sub);
  }

 private:
  void add(const char* key, const std::string& value) { text += prefix_ + key + "=" + value + "\n"; }
};

template <class P>
std::string fingerprint(const P& p) {
  Fingerprinter f;
  const_cast<P&>(p).visit(f);  // reads only
  return f.text;
}

// "" when every field of p (and of every struct nested in it) lies in its
// bounds and every check() passes, else the first problem, starting with the
// field's path ("clustering.tolerance must be > 0 m (got -1)")
template <class P>
std::string validate(const P& p) {
  Validator v;
  const_cast<P&>(p).visit(v);  // reads only
  if (!v.problem().empty()) return v.problem();
  return check_of(p);
}

// for constructors: throws std::invalid_argument("<what>: <problem>") when
// validate(p) fails
void require_valid_or_throw(const std::string& problem, const char* what);
template <class P>
const P& require_valid(const P& p, const char* what) {
  require_valid_or_throw(validate(p), what);
  return p;
}

}  // namespace paddock::params
