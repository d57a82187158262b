#pragma once
// summary.json read back (paddock plot draws the lap chart and the lap
// markers from it): the laps and the result, checked field by field, since
// the file may be anyone's
#include <string>
#include <vector>

namespace paddock::runner {

struct SummaryLaps {
  std::vector<double> start, time;
  std::vector<bool> timed;
  std::vector<int> doo, oc;
  double total_time = 0.0;
  bool finished = false;
  std::string scenario;  // the scenario's name
};

// the text of a summary.json; throws UserError "source: not a paddock
// summary: ..." naming the field that is missing or of the wrong kind (a
// count must be a whole number in int's range, a time a finite number)
SummaryLaps parse_summary(const std::string& text, const std::string& source);

}  // namespace paddock::runner
