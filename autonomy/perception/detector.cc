#include "autonomy/perception/detector.h"

namespace paddock::perception {

ConeDetector::~ConeDetector() = default;

}  // namespace paddock::perception
