// Accounting for every byte of an LCM log, and the one-line reasons an offline run gives.
#include <gtest/gtest.h>

#include "panmap/lcm/log_bytes.h"
#include "panmap/lcm/offline_mapping.h"

namespace panmap {
namespace {

TEST(LogByteAccount, EventsBackToBackLeaveNothingUnaccounted) {
  EXPECT_EQ(LogByteAccount::eventBytes(11, 100), 139u);  // 28-byte header + name + payload
  EXPECT_EQ(LogByteAccount::eventBytes(4, -5), 32u);     // a negative length counts as none
  LogByteAccount bytes;
  bytes.addEvent(139, 139);
  bytes.addEvent(50, 189);
  EXPECT_EQ(bytes.readableBytes(), 189u);
  EXPECT_EQ(bytes.skippedBytes(), 0u);
  EXPECT_FALSE(bytes.truncated(189));
  EXPECT_TRUE(bytes.truncated(190));
}

TEST(LogByteAccount, CountsGarbageBetweenEventsAndIgnoresImpossiblePositions) {
  LogByteAccount bytes;
  bytes.addEvent(100, 107);  // 7 bytes of garbage before the first event
  bytes.addEvent(50, 168);   // 11 more between the two
  bytes.addEvent(50, -1);    // ftell failed
  bytes.addEvent(500, 300);  // ends before it could have started
  EXPECT_EQ(bytes.readableBytes(), 168u);
  EXPECT_EQ(bytes.skippedBytes(), 18u);
}

TEST(OfflineReport, NamesTheLogsDamage) {
  OfflineReport report;
  report.log_bytes = 1000;
  report.readable_bytes = 1000;
  EXPECT_EQ(describeLogDamage(report), "");
  report.readable_bytes = 600;
  EXPECT_EQ(describeLogDamage(report), "unreadable after byte 600 of 1000 (truncated or corrupt)");
  report.skipped_bytes = 9;
  EXPECT_EQ(describeLogDamage(report),
            "unreadable after byte 600 of 1000 (truncated or corrupt); 9 bytes between events are "
            "not events");
  report.stopped_early = true;  // --max-frames: the rest was never read
  EXPECT_EQ(describeLogDamage(report), "9 bytes between events are not events");
}

TEST(OfflineReport, SaysWhyNothingWasMapped) {
  SessionOptions options;
  OfflineReport report;
  EXPECT_EQ(describeNothingMapped(report, options), "the log is empty");
  report.log_bytes = 1000;
  EXPECT_EQ(describeNothingMapped(report, options),
            "no LCM event in the log (not an LCM log, or corrupt from byte 0)");
  report.events = 7;
  report.channel_events = {{"IMU", 5}, {"CAMERA_POSE", 2}};
  EXPECT_EQ(describeNothingMapped(report, options),
            "no event on the RGB-D channel CAMERA_RGBD; the log has CAMERA_POSE (2), IMU (5)");
  report.channel_events["CAMERA_RGBD"] = 3;
  report.rejected = {{"frame: no pose", 2}, {"malformed CAMERA_RGBD", 1}};
  EXPECT_EQ(describeNothingMapped(report, options),
            "3 events on CAMERA_RGBD, no frame integrated; refused: frame: no pose (2), malformed "
            "CAMERA_RGBD (1)");
}

}  // namespace
}  // namespace panmap
