#pragma once
// numbers as text for reports and messages: one fixed-point formatter, so
// that every report prints a number the same way.
#include <string>

namespace paddock {

// v with `decimals` digits after the point, as printf's "%.*f" (e.g. fixed(2.5, 2)
// is "2.50"); at most 63 characters (longer text is cut)
std::string fixed(double v, int decimals);

}  // namespace paddock
