// the paper's tables as the program prints them: their shape, and what
// smoothing must do to a raw centreline (less curvature variation)
#include "sim/runner/reports.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <sstream>

#include "sim/runner/files.h"
#include "tests/runner/run_paddock.h"

namespace paddock::runner {
namespace {

using ::testing::HasSubstr;
const std::string kRoot = PADDOCK_SOURCE_DIR;

// the ours/paper cell of a row and column of the Markdown table
double ours(const std::string& table, const std::string& row, int column) {
  std::istringstream in(table);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("| " + row + " |", 0) != 0) continue;
    std::size_t pos = 0;
    for (int c = 0; c < column; ++c) pos = line.find('|', pos + 1);
    return std::strtod(line.c_str() + pos + 1, nullptr);
  }
  return -1.0;
}

TEST(Reports, SmoothingTableOnFsg2023) {
  const std::string t = report_smoothing(kRoot + "/tracks/fsg_2023.csv");
  EXPECT_THAT(t, HasSubstr("| | Raw | Moving Avg. | Opheim | Combined |"));
  // the combined smoothing varies its curvature less than the raw centreline,
  // and its velocity profile laps faster
  EXPECT_LT(ours(t, "Max CVR [1/m^2]", 4), ours(t, "Max CVR [1/m^2]", 1));
  EXPECT_LT(ours(t, "Mean CVR [1/m^2]", 4), ours(t, "Mean CVR [1/m^2]", 1));
  EXPECT_LT(ours(t, "Lap time [s]", 4), ours(t, "Lap time [s]", 1));
  // every path stays on the track: more than half a car from the boundary
  for (int c = 1; c <= 4; ++c) EXPECT_GT(ours(t, "Min dist. to bound [m]", c), 0.7);
  EXPECT_THROW(report_smoothing(kRoot + "/tracks/acceleration.csv"), UserError);
}

TEST(Reports, ControllersTableRunsAllThree) {
  // the paper's stack, whose table it is
  const std::string t = report_controllers(testing::with_paper(kRoot + "/scenarios/fsg_2019_autocross.ini"), {});
  for (const char* row : {"| Combined |", "| Stanley |", "| Pure pursuit |"}) EXPECT_THAT(t, HasSubstr(row));
  EXPECT_THAT(t, HasSubstr("143.0 / 0.201 / 0.645 / 40.772"));
  // Stanley tracks tighter than pure pursuit (RMS), as in the paper
  EXPECT_LT(ours(t, "Stanley", 2), ours(t, "Pure pursuit", 2));
  EXPECT_GT(ours(t, "Stanley", 2), 0.0);
}

}  // namespace
}  // namespace paddock::runner
