// the scenario INI dialect (sim/runner/ini.h): any text, with includes
// resolved against the repo's scenarios/ (so that an include of a real file
// splices it in, and a missing one or a cycle is the promised UserError)
#include <string>

#include "fuzz/fuzz_target.h"
#include "sim/runner/files.h"
#include "sim/runner/ini.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto entries = paddock::runner::parse_ini_text(text, "fuzz.ini", paddock::fuzz::source_dir() + "/scenarios/ci");
    for (const auto& e : entries) {
      if (e.line <= 0 || e.file.empty()) __builtin_trap();  // every entry says where it was written
    }
  } catch (const paddock::runner::UserError&) {
  }
  return 0;
}
