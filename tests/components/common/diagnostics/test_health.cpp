// The diagnostics level and status from successive counter reports.
#include <gtest/gtest.h>

#include "pixyslam/diagnostics/health.h"

namespace pixyslam::diagnostics {
namespace {

TEST(HealthTracker, WarnsNamingEachBadCounterThatGrewAndErrorWins) {
  HealthTracker t;
  Health h = t.update({{"samples", 10, false}, {"lines_rejected", 0, true}});
  EXPECT_EQ(h.level, Level::kOk);
  EXPECT_EQ(h.status, "");
  // Good counters may grow; a bad one that is not new grows by 3.
  h = t.update({{"samples", 20, false}, {"lines_rejected", 3, true}, {"bad_checksum", 0, true}});
  EXPECT_EQ(h.level, Level::kWarn);
  EXPECT_EQ(h.status, "lines_rejected +3");
  // Unchanged since the previous report: OK again.
  h = t.update({{"samples", 30, false}, {"lines_rejected", 3, true}, {"bad_checksum", 0, true}});
  EXPECT_EQ(h.level, Level::kOk);
  // A bad counter seen for the first time counts from 0; two grow.
  h = t.update({{"lines_rejected", 4, true}, {"bad_checksum", 2, true}, {"time_gaps", 1, true}});
  EXPECT_EQ(h.level, Level::kWarn);
  EXPECT_EQ(h.status, "lines_rejected +1, bad_checksum +2, time_gaps +1");
  h = t.update({{"lines_rejected", 9, true}}, "device '/dev/ttyACM0' is not open");
  EXPECT_EQ(h.level, Level::kError);
  EXPECT_EQ(h.status, "device '/dev/ttyACM0' is not open");
  EXPECT_STREQ(level_name(h.level), "ERROR");
}

}  // namespace
}  // namespace pixyslam::diagnostics
