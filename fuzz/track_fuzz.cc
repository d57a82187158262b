// a track file (sim/world/track.h): parsed, and when it parses, built into
// the track model and checked as `paddock check-track` does
#include <string>
#include <string_view>

#include "fuzz/fuzz_target.h"
#include "sim/world/track.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const paddock::world::TrackFile file = paddock::world::parse_track(text, "fuzz.csv");
    if (file.cones.size() != file.cone_lines.size()) __builtin_trap();
    const paddock::world::TrackModel model = paddock::world::build_track(file);
    (void)paddock::world::check_track_report(model, file);
  } catch (const paddock::world::TrackError&) {
  }
  return 0;
}
