// paddock: the command-line program (see `paddock help`)
#include <string>
#include <vector>

#include "sim/runner/cli.h"

int main(int argc, char** argv) {
  return paddock::runner::run_cli(std::vector<std::string>(argv + 1, argv + argc));
}
