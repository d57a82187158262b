#pragma once
// the paper's tables, computed here: `paddock report controllers SCENARIO`
// (Table I) and `paddock report smoothing TRACK` (Table II), as Markdown.
#include <string>
#include <vector>

namespace paddock::runner {

// runs the scenario with each lateral controller (combined, Stanley, pure
// pursuit) and tabulates ITAE, RMS and max lateral error and the mean lap time
// (laps 2 on when there are several) next to the paper's Table I
std::string report_controllers(const std::string& scenario_path, const std::vector<std::string>& overrides);

// plans the full lap of a track from its ground-truth cones (Delaunay and the
// centreline search from the start pose), smooths it four ways (raw, moving
// average, Opheim, combined), fits the spline and the velocity profile, and
// tabulates the lap time, the lateral acceleration at a constant 5 m/s, the
// curvature variation rate and the least distance to the boundaries next to
// the paper's Table II
std::string report_smoothing(const std::string& track_path);

}  // namespace paddock::runner
