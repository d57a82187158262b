#pragma once
// the paddock program run as a user runs it, for the runner's tests
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace paddock::testing {

struct Outcome {
  int code = -1;       // exit code; -1 when it did not exit normally
  std::string output;  // stdout and stderr together
};

inline Outcome run_paddock(const std::string& args) {
  Outcome o;
  FILE* p = popen((std::string(PADDOCK_BINARY) + " " + args + " 2>&1").c_str(), "r");
  if (!p) return o;
  std::array<char, 4096> buf{};
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) o.output.append(buf.data(), n);
  const int status = pclose(p);
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return o;
}

}  // namespace paddock::testing
