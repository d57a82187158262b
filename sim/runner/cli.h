#pragma once
// the `paddock` program's commands.
#include <string>
#include <vector>

namespace paddock::runner {

// runs a command line (argv without the program name); returns the exit code:
// 0 success, 2 bad usage or input, 3 a scenario's expectations failed
int run_cli(const std::vector<std::string>& args);

}  // namespace paddock::runner
