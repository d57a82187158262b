#include "autonomy/common/params.h"

#include <charconv>
#include <stdexcept>

namespace paddock::params {

std::string number(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string bounds_text(const Bounds& b, const char* unit) {
  const std::string u = unit && *unit ? std::string(" ") + unit : std::string();
  const bool has_lo = std::isfinite(b.lo), has_hi = std::isfinite(b.hi);
  if (!has_lo && !has_hi) return "a finite number" + u;
  if (!has_hi) return (b.lo_open ? "> " : ">= ") + number(b.lo) + u;
  if (!has_lo) return (b.hi_open ? "< " : "<= ") + number(b.hi) + u;
  return std::string("in ") + (b.lo_open ? "(" : "[") + number(b.lo) + ", " + number(b.hi) + (b.hi_open ? ")" : "]") + u;
}

void require_valid_or_throw(const std::string& problem, const char* what) {
  if (!problem.empty()) throw std::invalid_argument(std::string(what) + ": " + problem);
}

}  // namespace paddock::params
