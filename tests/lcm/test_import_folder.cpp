// panmap-import on the generic RGB-D folder built from real 7-Scenes frames: no flags needed,
// a corrupt file stops the import with its name, --skip-bad imports the rest and lists it.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "panmap/core/pose.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/text_files.h"
#include "panmap/lcm/log_import.h"
#include "test_helpers.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;
using test::binPath;
using test::runCommand;

constexpr int kFrames = 10;

// How a user's pose file may be written other than TUM's camera-to-world, x y z w, metres.
enum class PoseMistake { kNone, kWorldToCamera, kWxyz, kMillimetres };

// rgb/*.png (re-encoded from the JPEGs), depth/*.png (mm, the recorded files), intrinsic.txt
// (4x4) and gt_pose.txt (TUM, frame numbers as timestamps), its poses written with `mistake`.
void makeFolder(const test::TempDir& dir, PoseMistake mistake = PoseMistake::kNone,
                int frames = kFrames) {
  fs::create_directory(dir.path("rgb"));
  fs::create_directory(dir.path("depth"));
  std::ofstream poses(dir.path("gt_pose.txt"));
  poses.precision(17);
  for (int i = 0; i < frames; ++i) {
    char src[64], dst[32];
    std::snprintf(src, sizeof(src), "7scenes-200/frame-%06d", 3 * i);
    std::snprintf(dst, sizeof(dst), "%06d.png", i);
    const std::string stem = test::dataDir(src);
    fs::create_symlink(stem + ".depth.png", dir.path("depth/") + dst);
    writeFileBytes(dir.path("rgb/") + dst, encodePng(readColorFile(stem + ".color.jpg")));
    Eigen::Isometry3d T = nearestIsometry(readMatrixFile(stem + ".pose.txt", 4, 4));
    if (mistake == PoseMistake::kWorldToCamera) T = T.inverse();
    if (mistake == PoseMistake::kMillimetres) T.translation() *= 1000.0;
    const Eigen::Quaterniond q(T.linear());
    const Eigen::Vector3d t = T.translation();
    poses << i << " " << t.x() << " " << t.y() << " " << t.z() << " ";
    if (mistake == PoseMistake::kWxyz) {
      poses << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << "\n";
    } else {
      poses << q.x() << " " << q.y() << " " << q.z() << " " << q.w() << "\n";
    }
  }
  std::ofstream(dir.path("intrinsic.txt")) << "585 0 320 0\n0 585 240 0\n0 0 1 0\n0 0 0 1\n";
}

TEST(ImportFolder, CommonExportImportsWithNoFlags) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  makeFolder(dir);
  const auto r = runCommand(binPath("panmap-import") + " --quiet " + dir.path() + " " +
                            dir.path("out.lcmlog"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("(folder layout): 10 frames, 10 poses"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("0.001 m per unit (mm), detected"), std::string::npos) << r.output;

  // The same frames as the 7-Scenes reader sees them: identical depth, poses within the
  // printed precision.
  ImportOptions options;
  const ImportStats s = importDataset(dir.path(), dir.path("again.lcmlog"), options);
  ASSERT_EQ(s.recorded_poses.size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    char src[64];
    std::snprintf(src, sizeof(src), "7scenes-200/frame-%06d.pose.txt", 3 * i);
    const Eigen::Matrix4d T = readMatrixFile(test::dataDir(src), 4, 4);
    // The 7-Scenes files hold rounded, slightly non-orthonormal rotations; readers project them.
    EXPECT_LT(
        (s.recorded_poses[i].T_W_C.matrix() - nearestIsometry(T).matrix()).cwiseAbs().maxCoeff(),
        1e-9)
        << i;
    EXPECT_EQ(s.recorded_poses[i].frame_id, i);
  }
}

// The recorded 7-Scenes pose of folder frame i.
Eigen::Isometry3d truePose(int i) {
  char src[64];
  std::snprintf(src, sizeof(src), "7scenes-200/frame-%06d.pose.txt", 3 * i);
  return nearestIsometry(readMatrixFile(test::dataDir(src), 4, 4));
}

TEST(ImportFolder, PosesWrittenAnotherWayAreReadTheWayTheDepthAgreesWith) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  constexpr int kLonger = 40;  // 4 s of the recording: pairs 0.3 and 1 s apart
  const std::pair<PoseMistake, std::string> cases[] = {
      {PoseMistake::kNone, "read as camera-to-world, quaternion x y z w, metres: the depth"},
      {PoseMistake::kWorldToCamera, "read as world-to-camera, quaternion x y z w, metres:"},
      {PoseMistake::kWxyz, "read as camera-to-world, quaternion w x y z, metres:"},
      {PoseMistake::kMillimetres, "read as camera-to-world, quaternion x y z w, millimetres:"}};
  for (const auto& [mistake, note] : cases) {
    SCOPED_TRACE(note);
    test::TempDir dir;
    makeFolder(dir, mistake, kLonger);
    const ImportStats s = importDataset(dir.path(), dir.path("out.lcmlog"), ImportOptions());
    ASSERT_TRUE(s.pose_convention);
    EXPECT_EQ(s.pose_convention->note.rfind("poses: " + note, 0), 0u) << s.pose_convention->note;
    // panmap-import prints the notes.
    EXPECT_NE(std::find(s.notes.begin(), s.notes.end(), s.pose_convention->note), s.notes.end());
    EXPECT_EQ(s.pose_convention->changed, mistake != PoseMistake::kNone);
    EXPECT_GT(s.pose_convention->agreement_chosen, 0.5);
    ASSERT_EQ(s.recorded_poses.size(), static_cast<size_t>(kLonger));
    for (int i = 0; i < kLonger; ++i) {
      // Back to the recorded pose up to rounding (the file keeps 17 digits).
      EXPECT_LT((s.recorded_poses[i].T_W_C.matrix() - truePose(i).matrix()).cwiseAbs().maxCoeff(),
                1e-6)
          << i;
    }
  }
}

TEST(ImportFolder, APoseConventionTheUserGivesIsKeptAndDoubtedAloud) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  makeFolder(dir, PoseMistake::kWorldToCamera, 40);
  const auto r =
      runCommand(binPath("panmap-import") + " --quiet --pose-convention camera-to-world " +
                 dir.path() + " " + dir.path("out.lcmlog"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("poses: read as camera-to-world, quaternion x y z w, metres, but the "
                          "depth of 16 frame pairs agrees on only"),
            std::string::npos)
      << r.output;
  ImportOptions options;
  options.pose_convention.inverted = false;
  const ImportStats s = importDataset(dir.path(), dir.path("again.lcmlog"), options);
  ASSERT_TRUE(s.pose_convention);
  EXPECT_FALSE(s.pose_convention->changed);
  // Kept as written: world-to-camera.
  EXPECT_LT(
      (s.recorded_poses[5].T_W_C.matrix() - truePose(5).inverse().matrix()).cwiseAbs().maxCoeff(),
      1e-6);
}

// A frame whose depth is all zero maps nothing; it went by without a count.
TEST(ImportFolder, FramesWithoutDepthAreCounted) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  makeFolder(dir);
  fs::remove(dir.path("depth/000004.png"));
  writeFileBytes(dir.path("depth/000004.png"), encodeDepthPng(DepthImage(640, 480, 0)));
  const ImportStats s = importDataset(dir.path(), dir.path("out.lcmlog"), ImportOptions());
  EXPECT_EQ(s.frames_written, static_cast<size_t>(kFrames));
  EXPECT_EQ(s.frames_without_depth, 1u);
}

TEST(ImportFolder, ACorruptFileStopsTheImportUnlessSkipBad) {
  PANMAP_REQUIRE_DATA("7scenes-200");
  test::TempDir dir;
  makeFolder(dir);
  fs::remove(dir.path("depth/000004.png"));
  std::ofstream(dir.path("depth/000004.png")) << "\x89PNG\r\n\x1a\n truncated";
  const std::string import = binPath("panmap-import") + " --quiet " + dir.path() + " ";
  const auto stop = runCommand(import + dir.path("a.lcmlog"));
  EXPECT_EQ(stop.exit_code, 1);
  EXPECT_EQ(test::countLines(stop.output), 1) << stop.output;
  EXPECT_NE(stop.output.find("depth/000004.png"), std::string::npos) << stop.output;
  EXPECT_FALSE(fs::exists(dir.path("a.lcmlog")));

  const auto skip = runCommand(import + "--skip-bad " + dir.path("b.lcmlog"));
  ASSERT_EQ(skip.exit_code, 0) << skip.output;
  EXPECT_NE(skip.output.find("9 frames, 9 poses"), std::string::npos) << skip.output;
  EXPECT_NE(skip.output.find("skipped 1 bad frames"), std::string::npos) << skip.output;
  std::ifstream list(dir.path("b.lcmlog.skipped.txt"));
  std::stringstream listed;
  listed << list.rdbuf();
  EXPECT_NE(listed.str().find("depth/000004.png"), std::string::npos) << listed.str();
}

}  // namespace
}  // namespace panmap
