// the LiDAR's metadata file (autonomy/hal/ouster.h: the sensor's JSON as it
// reports it): parsed, checked, and when it passes, its layout derived
#include <stdexcept>
#include <string>

#include "autonomy/hal/ouster.h"
#include "fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace ouster = paddock::hal::ouster;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const ouster::SensorInfo info = ouster::parse_sensor_info(text, "fuzz.json");
    if (!ouster::check(info).empty()) return 0;
    (void)ouster::layout_of(info, paddock::hal::LidarLayout{});
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
