// Accounting for every byte of an LCM log, and the one-line reasons an offline run gives.
#include <gtest/gtest.h>

#include <fstream>

#include "panmap/lcm/conversions.h"
#include "panmap/lcm/log_bytes.h"
#include "panmap/lcm/log_info.h"
#include "panmap/lcm/log_writer.h"
#include "panmap/lcm/offline_mapping.h"
#include "test_helpers.h"

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

// liblcm allocates an event's claimed payload plus one byte before reading it: a header that
// claims 2^31 - 1 bytes overflowed that and crashed panmap-loginfo and panmap-mapper --log. Such
// a header is the log's damaged end, read up to and reported like a cut.
TEST(LogByteAccount, AHeaderClaimingMoreThanTheFileIsTheDamagedEnd) {
  test::TempDir dir;
  const std::string path = dir.path("claims.lcmlog");
  const uint8_t payload[5] = {1, 2, 3, 4, 5};
  {
    LogWriter writer(path);
    writer.writeRaw("A", 1, payload, sizeof(payload));
    writer.writeRaw("A", 2, payload, sizeof(payload));
  }
  const size_t whole = LogByteAccount::eventBytes(1, 5) * 2;
  {
    std::ofstream out(path, std::ios::binary | std::ios::app);
    // Sync word, event number and timestamp (zeros), a 1-byte channel, 2^31 - 1 payload bytes.
    uint8_t header[28] = {0xED, 0xA1, 0xDA, 0x01};
    header[23] = 1;
    header[24] = 0x7F;
    header[25] = header[26] = header[27] = 0xFF;
    out.write(reinterpret_cast<const char*>(header), sizeof(header));
    out << "A" << std::string(10, 'x');
  }
  std::FILE* file = std::fopen(path.c_str(), "rb");
  ASSERT_NE(file, nullptr);
  EXPECT_TRUE(nextEventFits(file, whole + 39));
  std::fseek(file, static_cast<long>(whole), SEEK_SET);
  EXPECT_FALSE(nextEventFits(file, whole + 39));
  EXPECT_EQ(std::ftell(file), static_cast<long>(whole));  // the position is restored
  std::fclose(file);

  const LogInfo info = inspectLog(path, false);
  EXPECT_EQ(info.events, 2u);
  EXPECT_EQ(info.readable_bytes, whole);
  EXPECT_TRUE(info.truncated);
}

// A channel name is bytes: one that is not UTF-8 made --json print nothing, a long one ran
// into the next column, and a newline in one broke the table.
TEST(LogInfo, AnyChannelNamePrints) {
  test::TempDir dir;
  const std::string path = dir.path("names.lcmlog");
  const uint8_t payload[3] = {1, 2, 3};
  {
    LogWriter writer(path);
    writer.writeRaw(
        "CAMERA\xff"
        "POSE",
        1, payload, sizeof(payload));
    writer.writeRaw("A_CHANNEL_NAME_LONGER_THAN_SIXTEEN", 2, payload, sizeof(payload));
    writer.writeRaw("TWO\nLINES", 3, payload, sizeof(payload));
  }
  const LogInfo info = inspectLog(path, false);
  ASSERT_EQ(info.channels.size(), 3u);
  const std::string json = logInfoToJson(info);
  EXPECT_NE(json.find("\"events\": 3"), std::string::npos) << json;
  const std::string table = logInfoToTable(info);
  EXPECT_NE(table.find("A_CHANNEL_NAME_LONGER_THAN_SIXTEEN  ?"), std::string::npos) << table;
  EXPECT_NE(table.find("TWO?LINES"), std::string::npos) << table;
  EXPECT_EQ(test::countLines(table), 1 + 3 + 3 + 1) << table;  // header, rows, failures, total
}

TEST(LogInfo, TheRateCountsOnlyMessagesThatDecode) {
  // Poses 100 ms apart by their utimes; garbage on the same channel, stamped by the logger's
  // clock (seconds since 1970), counted every pose twice and stretched the span to decades.
  test::TempDir dir;
  const std::string path = dir.path("rate.lcmlog");
  const uint8_t garbage[3] = {1, 2, 3};
  {
    LogWriter writer(path);
    for (int k = 0; k < 5; ++k) {
      StampedPose pose;
      pose.utime = 1000000 + 100000 * k;
      writer.write("CAMERA_POSE", 1700000000000000 + k, toMessage(pose));
      writer.writeRaw("CAMERA_POSE", 1700000000000000 + k, garbage, sizeof(garbage));
    }
    writer.writeRaw("ONLY_GARBAGE", 2000000, garbage, sizeof(garbage));
    writer.writeRaw("ONLY_GARBAGE", 2500000, garbage, sizeof(garbage));
  }
  const LogInfo info = inspectLog(path, false);
  ASSERT_EQ(info.channels.size(), 2u);
  const ChannelInfo& poses = info.channels[0];
  EXPECT_EQ(poses.count, 10u);
  EXPECT_EQ(poses.failures, 5u);
  EXPECT_EQ(poses.first_utime, 1000000);
  EXPECT_EQ(poses.last_utime, 1400000);
  EXPECT_NEAR(poses.rateHz(), 10.0, 1e-9);
  // A channel where nothing decodes still gets a rate, by the logger's clock.
  const ChannelInfo& garbage_only = info.channels[1];
  EXPECT_EQ(garbage_only.first_utime, 2000000);
  EXPECT_EQ(garbage_only.last_utime, 2500000);
  EXPECT_NEAR(garbage_only.rateHz(), 2.0, 1e-9);
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

// Masks logged on a channel the mapper does not read were ignored with exit 0 and no word.
TEST(OfflineReport, NamesTheChannelsLeftUnreadWhenNoMaskCame) {
  SessionOptions options;
  OfflineReport report;
  report.channel_events = {{"CAMERA_RGBD", 30}, {"CAMERA_POSE", 30}};
  EXPECT_EQ(describeUnreadChannels(report, options), "");  // a log without masks: nothing unread
  report.channel_events["PANMAP_POSE_CORRECTION"] = 1;
  EXPECT_EQ(describeUnreadChannels(report, options), "");
  report.channel_events["panoptic"] = 30;
  EXPECT_EQ(describeUnreadChannels(report, options),
            "no event on the panoptic channel PANOPTIC, so every frame was mapped without masks; "
            "the log also has panoptic (30), which no option names (--channel-panoptic)");
  report.channel_events["PANOPTIC"] = 30;  // masks read: the other channel is the user's
  EXPECT_EQ(describeUnreadChannels(report, options), "");
}

}  // namespace
}  // namespace panmap
