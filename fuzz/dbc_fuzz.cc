// a DBC file (autonomy/hal/dbc.h): parsed; when it parses, handed to the
// car's CAN codec, which checks that it carries the car's messages
#include <stdexcept>
#include <string>
#include <string_view>

#include "autonomy/hal/car_can.h"
#include "autonomy/hal/dbc.h"
#include "fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const paddock::hal::Dbc dbc = paddock::hal::parse_dbc(text, "fuzz.dbc");
    for (const paddock::hal::DbcMessage& m : dbc.messages) {
      if (m.line <= 0) __builtin_trap();  // every message says where it was written
    }
    paddock::hal::CarCan can(dbc, "fuzz.dbc");
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
