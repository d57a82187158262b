#pragma once
// the car tests' files: a file's bytes, and the sensors' shipped
// descriptions (scenarios/sensors: the Ouster's metadata, the car's DBC)
#include <fstream>
#include <sstream>
#include <string>

namespace paddock::car::testing {

inline std::string read(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

inline std::string shipped(const std::string& name) {
  return read(std::string(PADDOCK_SOURCE_DIR) + "/scenarios/sensors/" + name);
}

}  // namespace paddock::car::testing
