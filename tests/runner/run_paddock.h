#pragma once
// the paddock program run as a user runs it, for the runner's tests
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace paddock::testing {

struct Outcome {
  int code = -1;       // exit code; -1 when it did not exit normally
  std::string output;  // stdout and stderr together
};

// any shell command, its standard output (add 2>&1 for the errors too)
inline Outcome run_paddock_command(const std::string& command) {
  Outcome o;
  FILE* p = popen(command.c_str(), "r");
  if (!p) return o;
  std::array<char, 4096> buf{};
  std::size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) o.output.append(buf.data(), n);
  const int status = pclose(p);
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return o;
}

inline Outcome run_paddock(const std::string& args) {
  return run_paddock_command(std::string(PADDOCK_BINARY) + " " + args + " 2>&1");
}

// a shipped scenario with the paper's stack (scenarios/paper.ini after it),
// written to the temporary directory: the path of that file
inline std::string with_paper(const std::string& scenario) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / "paddock_paper_scenarios";
  std::filesystem::create_directories(d);
  const std::filesystem::path f = d / std::filesystem::path(scenario).filename();
  std::ofstream(f) << "include = " << scenario << "\ninclude = " << PADDOCK_SOURCE_DIR << "/scenarios/paper.ini\n";
  return f.string();
}

}  // namespace paddock::testing
