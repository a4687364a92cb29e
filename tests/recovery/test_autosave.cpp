// Crash recovery: periodic snapshots in stream time, atomic files, the frame journal, and
// resuming from the newest snapshot that loads (past a corrupt one) exactly as if never
// interrupted.
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "lcm/synthetic_stream.h"
#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"
#include "panmap/recovery/autosave.h"
#include "panmap/recovery/resume.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;

void integrate(Mapper* mapper, const test::SyntheticStream& s, size_t k) {
  mapper->integrate(s.frames[k], s.poses[k].T_W_C, &s.masks[k], s.poses[k].source);
}

// Maps the 12-frame stream (frames 333 ms apart) with a 1 s autosave period.
void mapWithAutosave(const std::string& dir) {
  const test::SyntheticStream& s = test::syntheticStream();
  Mapper mapper(test::streamMapperConfig());
  Autosaver::Config config;
  config.dir = dir;
  config.period_s = 1.0;
  Autosaver autosaver(config);
  for (size_t k = 0; k < s.frames.size(); ++k) {
    integrate(&mapper, s, k);
    autosaver.afterFrame(mapper, s.frames[k].frame_id, s.frames[k].utime);
  }
  autosaver.wait();
  // Frame 0 starts the clock; frames 3, 6 and 9 are each 1 s of stream time after the last.
  EXPECT_EQ(autosaver.stats().written, 3);
  EXPECT_EQ(autosaver.stats().failed, 0);
}

TEST(Autosaver, SnapshotsEveryPeriodOfStreamTimeAndKeepsTheNewestTwo) {
  test::TempDir dir;
  mapWithAutosave(dir.path());
  const std::vector<std::string> kept = listAutosaves(dir.path());
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept[0], autosavePath(dir.path(), 3));
  EXPECT_EQ(kept[1], autosavePath(dir.path(), 2));
  EXPECT_EQ(Mapper::load(kept[0])->framesIntegrated(), 10);  // frames 0-9
  EXPECT_EQ(Mapper::load(kept[1])->framesIntegrated(), 7);   // frames 0-6
  EXPECT_FALSE(fs::exists(kept[0] + ".partial"));
  // The journal: a run marker, then one line per frame.
  std::ifstream journal(dir.path("frames.journal"));
  std::string line;
  int frames = 0, markers = 0;
  while (std::getline(journal, line)) (line[0] == '#' ? markers : frames)++;
  EXPECT_EQ(markers, 1);
  EXPECT_EQ(frames, 12);

  // A second run in the same folder continues the numbering.
  Autosaver::Config config;
  config.dir = dir.path();
  Autosaver again(config);
  again.snapshotNow(*Mapper::load(kept[1]));
  again.wait();
  EXPECT_EQ(listAutosaves(dir.path())[0], autosavePath(dir.path(), 4));
  again.clear();
  EXPECT_TRUE(listAutosaves(dir.path()).empty());
  // Nothing is left behind: an empty journal read as a run that had not finished.
  EXPECT_FALSE(fs::exists(dir.path("frames.journal")));
  EXPECT_FALSE(fs::exists(dir.path()));
}

// The loop-closure store is written behind the map on a thread of its own: a snapshot taken
// ahead of it, resumed after a crash, held frames the store never got, and a later correction
// of them was refused. A snapshot now waits for the store to hold its newest frame.
TEST(Autosaver, ASnapshotWaitsForTheFrameStoreToHoldItsNewestFrame) {
  const test::SyntheticStream& s = test::syntheticStream();
  Mapper mapper(test::streamMapperConfig());
  integrate(&mapper, s, 0);
  test::TempDir dir;
  Autosaver::Config config;
  config.dir = dir.path();
  std::atomic<int> asked{0};
  std::atomic<int64_t> asked_utime{0};
  config.frame_stored = [&](int64_t utime) {
    asked_utime = utime;
    return ++asked > 3;  // the writer catches up after a few polls
  };
  {
    Autosaver autosaver(config);
    autosaver.afterFrame(mapper, s.frames[0].frame_id, s.frames[0].utime);
    autosaver.snapshotNow(mapper);
    autosaver.wait();
    EXPECT_GE(asked.load(), 4);
    EXPECT_EQ(asked_utime.load(), s.frames[0].utime);
    EXPECT_EQ(autosaver.stats().ahead_of_store, 0);
    EXPECT_EQ(autosaver.stats().written, 1);
  }
  // A store that never catches up (its writes fail) delays the snapshot by store_wait_s at
  // most; the snapshot is taken and counted.
  config.frame_stored = [](int64_t) { return false; };
  config.store_wait_s = 0.01;
  Autosaver autosaver(config);
  autosaver.afterFrame(mapper, s.frames[0].frame_id, s.frames[0].utime);
  autosaver.snapshotNow(mapper);
  autosaver.wait();
  EXPECT_EQ(autosaver.stats().ahead_of_store, 1);
  EXPECT_EQ(autosaver.stats().written, 1);
}

// Failing snapshots went to stderr only; the live status warns while the newest one failed.
TEST(Autosaver, TheLastSnapshotsFailureIsKnownUntilOneSucceeds) {
  const test::SyntheticStream& s = test::syntheticStream();
  Mapper mapper(test::streamMapperConfig());
  integrate(&mapper, s, 0);
  test::TempDir dir;
  Autosaver::Config config;
  config.dir = dir.path("auto");
  Autosaver autosaver(config);
  fs::rename(dir.path("auto"), dir.path("moved"));
  std::ofstream(dir.path("auto")) << "a file where the folder was";
  autosaver.snapshotNow(mapper);
  autosaver.wait();
  EXPECT_TRUE(autosaver.stats().last_failed);
  EXPECT_EQ(autosaver.stats().failed, 1);
  fs::remove(dir.path("auto"));
  fs::rename(dir.path("moved"), dir.path("auto"));
  autosaver.snapshotNow(mapper);
  autosaver.wait();
  EXPECT_FALSE(autosaver.stats().last_failed);
  EXPECT_EQ(autosaver.stats().written, 1);
  // The folder removed under the running mapper (with the output folder around it): the next
  // snapshot makes it again, and the journal goes on in it (every later snapshot failed).
  fs::remove_all(dir.path("auto"));
  integrate(&mapper, s, 1);
  autosaver.afterFrame(mapper, s.frames[1].frame_id, s.frames[1].utime);
  autosaver.snapshotNow(mapper);
  autosaver.wait();
  EXPECT_FALSE(autosaver.stats().last_failed);
  EXPECT_EQ(autosaver.stats().written, 2);
  EXPECT_EQ(listAutosaves(dir.path("auto")).size(), 1u);
  integrate(&mapper, s, 2);
  autosaver.afterFrame(mapper, s.frames[2].frame_id, s.frames[2].utime);
  const std::string journal = test::fileBytes(dir.path("auto/frames.journal"));
  EXPECT_NE(
      journal.find(std::to_string(s.frames[2].frame_id) + " " + std::to_string(s.frames[2].utime)),
      std::string::npos)
      << journal;
}

TEST(Resume, SkipsACorruptSnapshotListsLostFramesAndContinuesExactly) {
  test::TempDir dir;
  mapWithAutosave(dir.path());
  // The newest snapshot cut short, as a disk could leave it.
  const std::string newest = autosavePath(dir.path(), 3);
  fs::resize_file(newest, fs::file_size(newest) / 2);

  ResumePoint point = resumeFrom(dir.path());
  EXPECT_EQ(point.path, autosavePath(dir.path(), 2));
  ASSERT_EQ(point.refused.size(), 1u);
  EXPECT_NE(point.refused[0].find("autosave-000003.panmap: truncated map file"), std::string::npos)
      << point.refused[0];
  const test::SyntheticStream& s = test::syntheticStream();
  EXPECT_EQ(point.frames, 7);
  EXPECT_EQ(point.last_utime, s.frames[6].utime);
  EXPECT_EQ(point.last_frame_id, s.frames[6].frame_id);
  ASSERT_EQ(point.lost.size(), 5u);  // frames 7-11 were journaled after it
  EXPECT_EQ(point.lost.front().first, s.frames[7].frame_id);
  EXPECT_EQ(point.lost.back().second, s.frames[11].utime);
  EXPECT_NE(describeResume(point).find("lost 5 frames"), std::string::npos)
      << describeResume(point);
  // Without its journal a resume cannot know what was lost, and says so (it said nothing was).
  fs::rename(dir.path("frames.journal"), dir.path("journal.kept"));
  EXPECT_NE(describeResume(resumeFrom(dir.path()))
                .find("the frame journal is missing or unreadable: frames lost since it are not "
                      "known"),
            std::string::npos);
  fs::rename(dir.path("journal.kept"), dir.path("frames.journal"));

  // Mapping on from the snapshot equals never stopping.
  for (size_t k = 7; k < s.frames.size(); ++k) integrate(point.mapper.get(), s, k);
  Mapper uninterrupted(test::streamMapperConfig());
  for (size_t k = 0; k < s.frames.size(); ++k) integrate(&uninterrupted, s, k);
  EXPECT_EQ(test::mapBytes(*point.mapper), test::mapBytes(uninterrupted));
}

TEST(Resume, TakesACompletePartialSnapshotAndRefusesACutOne) {
  // A kill after the snapshot was streamed but before its fsync and rename leaves it complete
  // under .partial: resuming from it loses nothing beyond it.
  test::TempDir dir;
  mapWithAutosave(dir.path());
  const std::string newest = autosavePath(dir.path(), 3);
  fs::rename(newest, newest + ".partial");
  ResumePoint point = resumeFrom(dir.path());
  EXPECT_EQ(point.path, newest + ".partial");
  EXPECT_EQ(point.frames, 10);
  EXPECT_TRUE(point.refused.empty());
  // Cut short, as a kill while streaming leaves it: refused, the complete one before it taken.
  fs::resize_file(newest + ".partial", fs::file_size(newest + ".partial") - 100);
  point = resumeFrom(dir.path());
  EXPECT_EQ(point.path, autosavePath(dir.path(), 2));
  ASSERT_EQ(point.refused.size(), 1u);
  EXPECT_NE(point.refused[0].find(".partial: truncated map file"), std::string::npos);
  // A new run numbers its snapshots after the leftover, and clears it at the end. Resumed, it
  // removes the partial files of earlier crashes but the one it resumed from.
  const std::string older_partial = autosavePath(dir.path(), 1) + ".partial";
  fs::copy_file(autosavePath(dir.path(), 2), older_partial);
  Autosaver::Config config;
  config.dir = dir.path();
  config.resumed_from = point.path;
  Autosaver again(config);
  EXPECT_FALSE(fs::exists(newest + ".partial"));  // the cut one
  EXPECT_FALSE(fs::exists(older_partial));
  EXPECT_TRUE(fs::exists(point.path));
  again.snapshotNow(*point.mapper);
  again.wait();
  EXPECT_EQ(listAutosaves(dir.path())[0], autosavePath(dir.path(), 4));
  again.clear();
  EXPECT_TRUE(listResumeCandidates(dir.path()).empty());
}

TEST(Resume, AMapFileNewerThanTheSnapshotsIsTaken) {
  // A mapper killed while it wrote its final outputs had map.panmap whole (it goes first):
  // resuming from the snapshot before it lost every frame since, then overwrote it.
  test::TempDir dir;
  mapWithAutosave(dir.path("autosave"));
  const test::SyntheticStream& s = test::syntheticStream();
  Mapper whole(test::streamMapperConfig());
  for (size_t k = 0; k < s.frames.size(); ++k) integrate(&whole, s, k);
  const std::string map = dir.path("map.panmap");
  whole.save(map);
  const auto snapshot_time = fs::last_write_time(autosavePath(dir.path("autosave"), 3));
  fs::last_write_time(map, snapshot_time + std::chrono::seconds(1));
  ResumePoint point = resumeFrom(dir.path("autosave"), {map});
  EXPECT_EQ(point.path, map);
  EXPECT_EQ(point.frames, 12);
  EXPECT_TRUE(point.lost.empty());  // the journal holds no frame after its newest
  EXPECT_EQ(test::mapBytes(*point.mapper), test::mapBytes(whole));
  // An older map file (a finished run's, before this run's snapshots) is not taken.
  fs::last_write_time(map, snapshot_time - std::chrono::seconds(1));
  point = resumeFrom(dir.path("autosave"), {map});
  EXPECT_EQ(point.path, autosavePath(dir.path("autosave"), 3));
  EXPECT_EQ(point.frames, 10);
  // Nothing but the map file: it is taken (an export's map, before the first snapshot).
  for (const std::string& path : listResumeCandidates(dir.path("autosave"))) fs::remove(path);
  EXPECT_EQ(resumeFrom(dir.path("autosave"), {map}).path, map);
  // Neither: one error that says what to do.
  fs::remove(map);
  test::expectError([&] { resumeFrom(dir.path("autosave"), {map}); },
                    {"no autosave-NNNNNN.panmap snapshot to resume from and no " + map,
                     "start it without --resume"});
}

TEST(Resume, NoLoadableSnapshotIsOneClearError) {
  test::TempDir dir;
  EXPECT_THROW(resumeFrom(dir.path()), Error);
  std::ofstream(autosavePath(dir.path(), 1)) << "not a map";
  try {
    resumeFrom(dir.path());
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no snapshot loads"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("autosave-000001.panmap"), std::string::npos);
  }
}

TEST(MapFile, CorruptionIsNamedWithFileAndOffset) {
  test::TempDir dir;
  Mapper mapper(test::streamMapperConfig());
  integrate(&mapper, test::syntheticStream(), 0);
  std::vector<uint8_t> bytes = mapper.serialize();
  const size_t size = bytes.size();
  auto error = [&](const std::vector<uint8_t>& b) -> std::string {
    try {
      Mapper::deserialize(b, "m.panmap");
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(error(bytes), "");
  std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + static_cast<long>(size / 3));
  EXPECT_EQ(error(cut), "m.panmap: truncated map file (" + std::to_string(size / 3) +
                            " bytes; the header at offset 12 announces " + std::to_string(size) +
                            ")");
  bytes[size / 2] ^= 0x40;
  EXPECT_EQ(error(bytes), "m.panmap: checksum mismatch over bytes 20-" + std::to_string(size - 4) +
                              " (corrupt map file)");
  EXPECT_NE(error({'P', 'A', 'N'}).find("m.panmap: truncated"), std::string::npos);
  // Cut while it was written (a snapshot's .partial after a kill): the size, filled in last, is
  // still 0. It read as "overlong ... announces 24".
  std::vector<uint8_t> unfinished(bytes.begin(), bytes.begin() + static_cast<long>(size / 2));
  for (size_t k = 12; k < 20; ++k) unfinished[k] = 0;
  EXPECT_EQ(error(unfinished), "m.panmap: unfinished map file (" + std::to_string(size / 2) +
                                   " bytes; its writer stopped before the end, the header's size "
                                   "was never filled in)");
}

// load() streams the file (parsing as it reads, the checksum compared at the end) instead of
// reading it whole first: the same map and the same one-line errors as deserialize().
TEST(MapFile, LoadingAFileGivesWhatDeserializingItsBytesGives) {
  test::TempDir dir;
  Mapper mapper(test::streamMapperConfig());
  integrate(&mapper, test::syntheticStream(), 0);
  const std::vector<uint8_t> bytes = mapper.serialize();
  const size_t size = bytes.size();
  const std::string path = dir.path("m.panmap");
  auto write = [&](const std::vector<uint8_t>& b) {
    std::ofstream(path, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
  };
  auto loadError = [&](const std::vector<uint8_t>& b) -> std::string {
    write(b);
    try {
      Mapper::load(path);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  auto deserializeError = [&](const std::vector<uint8_t>& b) -> std::string {
    try {
      Mapper::deserialize(b, path);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  write(bytes);
  EXPECT_EQ(Mapper::load(path)->serialize(), bytes);

  std::vector<std::vector<uint8_t>> bad;
  bad.emplace_back(bytes.begin(), bytes.begin() + static_cast<long>(size / 3));  // truncated
  bad.push_back(bytes);
  bad.back().push_back(0);  // overlong
  bad.push_back(bytes);
  bad.back()[size / 2] ^= 0x40;  // a voxel byte: parses, the checksum disagrees
  bad.push_back(bytes);
  bad.back()[size - 1] ^= 0x01;  // the checksum itself
  // Early payload bytes (the config) set to 0xFF: whatever the parsing makes of them first, the
  // error names the corruption.
  bad.push_back(bytes);
  for (size_t i = 0; i < 8; ++i) bad.back()[100 + i] = 0xFF;
  bad.push_back({'P', 'A', 'N'});
  bad.push_back({'N', 'O', 'T', 'A', 'M', 'A', 'P', '!', 0, 0, 0, 0});
  for (const std::vector<uint8_t>& b : bad) {
    const std::string expected = deserializeError(b);
    EXPECT_FALSE(expected.empty());
    EXPECT_EQ(loadError(b), expected);
  }
  EXPECT_NE(loadError(bad[2]).find("checksum mismatch"), std::string::npos);
  EXPECT_NE(loadError(bad[4]).find("checksum mismatch"), std::string::npos);
  EXPECT_EQ(loadError(bad[1]), path + ": overlong map file (" + std::to_string(size + 1) +
                                   " bytes; the header at offset 12 announces " +
                                   std::to_string(size) + ")");
}

TEST(AtomicFile, ReplacesWholeFilesAndNamesFailures) {
  test::TempDir dir;
  const std::string path = dir.path("f.bin");
  auto write = [](const std::string& to, const std::string& text) {
    AtomicFileWriter file(to);
    file.append(reinterpret_cast<const uint8_t*>(text.data()), text.size());
    file.commit();
  };
  write(path, "first");
  write(path, "second!");
  EXPECT_EQ(test::fileBytes(path), "second!");
  EXPECT_FALSE(fs::exists(path + ".partial"));
  try {
    write(dir.path("missing/f.bin"), "x");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot create " + dir.path("missing/f.bin.partial")),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace panmap
