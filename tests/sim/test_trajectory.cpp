#include <cmath>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "panmap/core/error.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/sequence.h"
#include "panmap/sim/trajectory.h"
#include "test_helpers.h"

namespace panmap {
namespace {

// Exact distance from a point to a triangle (Ericson, Real-Time Collision Detection 5.1.5).
double pointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return (p - a).norm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return (p - b).norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return (p - c).norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  }
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

// Smallest distance from every pose to every triangle of the mesh.
double exactClearance(const std::vector<StampedPose>& poses, const LabelledMesh& mesh) {
  double clearance = 1e9;
  for (const StampedPose& pose : poses) {
    for (const Eigen::Vector3i& f : mesh.faces) {
      clearance = std::min(clearance, pointTriangleDistance(pose.T_W_C.translation(),
                                                            mesh.vertices[f[0]].cast<double>(),
                                                            mesh.vertices[f[1]].cast<double>(),
                                                            mesh.vertices[f[2]].cast<double>()));
    }
  }
  return clearance;
}

class SurveyOfRoom : public ::testing::TestWithParam<int> {};

TEST_P(SurveyOfRoom, StaysClearSmoothAndAtHeadHeight) {
  const ProceduralRoom room = generateRoom(static_cast<uint64_t>(GetParam()));
  SurveyConfig config;
  config.num_frames = 1800;
  const std::vector<StampedPose> traj = planSurvey(room.mesh, config, 7);
  ASSERT_EQ(traj.size(), 1800u);
  const double dt = 1.0 / config.rate_hz;
  double max_turn = 0.0, max_step = 0.0;
  for (size_t k = 0; k < traj.size(); ++k) {
    const Eigen::Isometry3d& T = traj[k].T_W_C;
    ASSERT_TRUE(T.matrix().allFinite()) << k;
    EXPECT_EQ(traj[k].utime, std::llround(k * dt * 1e6));
    EXPECT_GE(T.translation().z(), config.min_height_m - 1e-9);
    EXPECT_LE(T.translation().z(), config.max_height_m + 1e-9);
    // Optical frame: x right, level (no roll), y pointing down-ish.
    EXPECT_NEAR(T.linear().col(0).z(), 0.0, 1e-9);
    EXPECT_GT(T.linear().col(1).z(), 0.0 - 1.0);
    if (k > 0) {
      const Eigen::Isometry3d& P = traj[k - 1].T_W_C;
      max_step = std::max(max_step, (T.translation() - P.translation()).head<2>().norm());
      max_turn = std::max(
          max_turn, std::acos(std::clamp(T.linear().col(2).dot(P.linear().col(2)), -1.0, 1.0)));
    }
  }
  EXPECT_LE(max_step, config.speed_mps * dt * 1.01);
  const double max_rate = (config.max_yaw_rate_dps + config.max_pitch_rate_dps) * M_PI / 180.0 * dt;
  EXPECT_LE(max_turn, max_rate + 1e-9);
  // Exact clearance against every triangle, for every 30th pose.
  std::vector<StampedPose> sampled;
  for (size_t k = 0; k < traj.size(); k += 30) sampled.push_back(traj[k]);
  const double clearance = exactClearance(sampled, room.mesh);
  EXPECT_GE(clearance, config.clearance_m);
  EXPECT_GE(minClearance(sampled, room.mesh),
            clearance - 1e-6);  // vertices are never nearer than faces
  // Same seed, same trajectory.
  const auto again = planSurvey(room.mesh, config, 7);
  EXPECT_EQ(again.back().T_W_C.matrix(), traj.back().T_W_C.matrix());
}

TEST_P(SurveyOfRoom, MostObjectsAreSeenFromThreeViewpoints) {
  const ProceduralRoom room = generateRoom(static_cast<uint64_t>(GetParam()));
  SurveyConfig survey;
  survey.num_frames = 3600;  // a 2-minute scan
  SynthConfig config;
  config.camera = PinholeCamera{131.25, 131.25, 79.375, 59.375, 160, 120};  // 640x480 / 4
  config.min_view_px = 200 / 16;
  config.masks = SegmenterNoiseConfig::fromPreset("clean");
  config.depth.enabled = false;
  SequenceSynthesizer synth(room.mesh, planSurvey(room.mesh, survey, 7), config);
  for (size_t k = 0; k < synth.size(); k += 6) synth.frame(k);
  const CoverageStats coverage = synth.coverage();
  EXPECT_GT(coverage.thing_instances, 10);
  EXPECT_GE(coverage.fractionSeenFrom3Views(), 0.6)
      << coverage.seen_from_3_views << " of " << coverage.thing_instances;
  RecordProperty("fraction_seen_from_3_views", std::to_string(coverage.fractionSeenFrom3Views()));
}

INSTANTIATE_TEST_SUITE_P(Seeds, SurveyOfRoom, ::testing::Values(1, 2, 3));

TEST(Survey, NoRoomToWalkIsAClearError) {
  LabelledMesh mesh;
  mesh.vertices = {{0, 0, 0}, {0.5, 0, 0}, {0, 0.5, 0}};  // 0.125 m^2 of floor
  mesh.faces = {{0, 1, 2}};
  try {
    planSurvey(mesh, SurveyConfig(), 1);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no room to walk"), std::string::npos) << e.what();
  }
}

// Two-triangle rectangle p00, p10 = p00 + u, p01 = p00 + v, with labels.
void addRect(LabelledMesh* mesh, const Eigen::Vector3f& p00, const Eigen::Vector3f& u,
             const Eigen::Vector3f& v, int32_t instance, int32_t semantic) {
  const auto base = static_cast<int32_t>(mesh->vertices.size());
  for (const Eigen::Vector3f& p :
       {p00, Eigen::Vector3f(p00 + u), Eigen::Vector3f(p00 + u + v), Eigen::Vector3f(p00 + v)}) {
    mesh->vertices.push_back(p);
    mesh->instance.push_back(instance);
    mesh->semantic.push_back(semantic);
  }
  mesh->faces.emplace_back(base, base + 1, base + 2);
  mesh->faces.emplace_back(base, base + 2, base + 3);
}

// Frames whose view turns toward `target` (within 10 degrees) and away from the walking
// direction (more than 30 degrees): the head has picked it.
int looksAt(const std::vector<StampedPose>& poses, const Eigen::Vector2d& target) {
  int n = 0;
  for (size_t k = 1; k < poses.size(); ++k) {
    const Eigen::Vector2d eye = poses[k].T_W_C.translation().head<2>();
    const Eigen::Vector2d walk = eye - poses[k - 1].T_W_C.translation().head<2>();
    const Eigen::Vector2d forward = poses[k].T_W_C.linear().col(2).head<2>().normalized();
    const Eigen::Vector2d to_target = (target - eye).normalized();
    if (walk.norm() < 1e-6) continue;
    if (forward.dot(to_target) > std::cos(10.0 * M_PI / 180.0) &&
        forward.dot(walk.normalized()) < std::cos(30.0 * M_PI / 180.0)) {
      ++n;
    }
  }
  return n;
}

TEST(Survey, WallsHideObjectsBehindThemWhenAsked) {
  // Two rooms side by side, a solid wall at x = 3.5 between them (class wall, full height); a
  // 0.5 m box (a chair's class) stands in the smaller east room, the walk keeps to the west one
  // (the planner walks the largest free region).
  LabelledMesh mesh;
  const Eigen::Vector3f x = Eigen::Vector3f::UnitX(), y = Eigen::Vector3f::UnitY(),
                        z = Eigen::Vector3f::UnitZ();
  addRect(&mesh, Eigen::Vector3f::Zero(), 6.0f * x, 3.0f * y, 2, 2);  // floor
  addRect(&mesh, Eigen::Vector3f::Zero(), 6.0f * x, 2.5f * z, 1, 1);  // south wall
  addRect(&mesh, 3.0f * y, 6.0f * x, 2.5f * z, 1, 1);                 // north wall
  addRect(&mesh, Eigen::Vector3f::Zero(), 3.0f * y, 2.5f * z, 1, 1);  // west wall
  addRect(&mesh, 6.0f * x, 3.0f * y, 2.5f * z, 1, 1);                 // east wall
  addRect(&mesh, 3.5f * x, 3.0f * y, 2.5f * z, 1, 1);                 // the wall between
  const Eigen::Vector3f lo(4.5f, 1.25f, 0.0f);
  for (int i = 0; i < 2; ++i) {  // six faces, 24 vertices: enough to be a target
    addRect(&mesh, lo + i * 0.5f * x, 0.5f * y, 0.5f * z, 10, 5);
    addRect(&mesh, lo + i * 0.5f * y, 0.5f * x, 0.5f * z, 10, 5);
    addRect(&mesh, lo + i * 0.5f * z, 0.5f * x, 0.5f * y, 10, 5);
  }
  SurveyConfig config;
  config.num_frames = 600;
  config.rate_hz = 10.0;
  const std::vector<Eigen::Vector2d> stops = {{0.8, 0.8}, {2.7, 0.8}, {2.7, 2.2}, {0.8, 2.2}};
  const Eigen::Vector2d chair(4.75, 1.5);
  const std::vector<StampedPose> seen_through = planSurveyThrough(mesh, config, stops, 1);
  config.walls_block_view = true;
  const std::vector<StampedPose> blocked = planSurveyThrough(mesh, config, stops, 1);
  for (const StampedPose& p : blocked) ASSERT_LT(p.T_W_C.translation().x(), 3.5);
  EXPECT_GT(looksAt(seen_through, chair), 30);
  EXPECT_EQ(looksAt(blocked, chair), 0);
}

// A bathroom of w x d metres (walls 2.5 m high) with a 0.4 m wide cabinet 1.8 m tall in one
// corner: within the camera's height band, as a shelf or a shower cabin would be.
LabelledMesh bathroom(float w, float d) {
  const Eigen::Vector3f x = Eigen::Vector3f::UnitX(), y = Eigen::Vector3f::UnitY(),
                        z = Eigen::Vector3f::UnitZ();
  LabelledMesh mesh;
  addRect(&mesh, Eigen::Vector3f::Zero(), w * x, d * y, 2, 2);  // floor
  addRect(&mesh, Eigen::Vector3f::Zero(), w * x, 2.5f * z, 1, 1);
  addRect(&mesh, d * y, w * x, 2.5f * z, 1, 1);
  addRect(&mesh, Eigen::Vector3f::Zero(), d * y, 2.5f * z, 1, 1);
  addRect(&mesh, w * x, d * y, 2.5f * z, 1, 1);
  const Eigen::Vector3f lo(w - 0.4f, d - 0.4f, 0.0f);
  for (int i = 0; i < 2; ++i) {
    addRect(&mesh, lo + i * 0.4f * x, 0.4f * y, 1.8f * z, 10, 39);
    addRect(&mesh, lo + i * 0.4f * y, 0.4f * x, 1.8f * z, 10, 39);
    addRect(&mesh, lo + i * 1.8f * z, 0.4f * x, 0.4f * y, 10, 39);
  }
  return mesh;
}

TEST(Survey, ASmallRoomIsWalkedCloserToItsWalls) {
  SurveyConfig config;
  config.num_frames = 400;
  config.rate_hz = 5.0;
  config.laps = 2;
  // 2 x 1.5 m leaves 0.98 m^2 at 0.3 m: walked at 0.2 m.
  const LabelledMesh small = bathroom(2.0f, 1.5f);
  const SurveyPath path = planSurveyPath(small, config, 1);
  EXPECT_NEAR(path.clearance_m, 0.2, 1e-9);
  const std::vector<StampedPose> poses = planSurvey(small, config, 1);
  ASSERT_EQ(poses.size(), 400u);
  EXPECT_GE(exactClearance(poses, small), path.clearance_m);
  // 1.2 x 1.5 m needs min_clearance_m itself.
  const LabelledMesh smaller = bathroom(1.2f, 1.5f);
  EXPECT_NEAR(planSurveyPath(smaller, config, 1).clearance_m, config.min_clearance_m, 1e-9);
  EXPECT_GE(exactClearance(planSurvey(smaller, config, 1), smaller), config.min_clearance_m);
  // A room that has the floor keeps the configured clearance.
  EXPECT_EQ(planSurveyPath(bathroom(2.4f, 2.5f), config, 1).clearance_m, config.clearance_m);
  // Without a lower clearance to fall back to, a room with under 0.25 m^2 clear at 0.3 m is a
  // clear error.
  config.min_clearance_m = config.clearance_m;
  try {
    planSurvey(bathroom(1.2f, 1.2f), config, 1);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no room to walk"), std::string::npos) << e.what();
  }
}

// Ten stops over any floor walked a 150 m^2 floor of four rooms past 10 places, and most of
// its things were never seen from three viewpoints: a large floor gets one stop per
// area_per_stop_m2, rooms the size the defaults were set on keep their 10.
TEST(Survey, ALargeFloorGetsStopsAsDenseAsARoom) {
  SurveyConfig config;
  config.rate_hz = 5.0;
  const LabelledMesh hall = bathroom(12.0f, 10.0f);
  const SurveyPath dense = planSurveyPath(hall, config, 3);
  ASSERT_GT(dense.free_area_m2, 90.0);
  EXPECT_EQ(dense.stops.size(),
            static_cast<size_t>(std::ceil(dense.free_area_m2 / config.area_per_stop_m2)));
  SurveyConfig fixed = config;
  fixed.area_per_stop_m2 = 0.0;
  const SurveyPath sparse = planSurveyPath(hall, fixed, 3);
  EXPECT_EQ(sparse.stops.size(), 10u);
  EXPECT_EQ(sparse.free_area_m2, dense.free_area_m2);
  // The farthest point of the free floor from every stop: how far the walk may pass from
  // what stands there (the hall's floor inside 0.4 m of its walls, on a 0.25 m grid).
  auto reach = [](const SurveyPath& path) {
    double worst = 0.0;
    for (double x = 0.4; x <= 11.6; x += 0.25) {
      for (double y = 0.4; y <= 9.6; y += 0.25) {
        if (x > 11.2 && y > 9.2) continue;  // the cabinet's corner
        double nearest = 1e9;
        for (const Eigen::Vector2d& s : path.stops) {
          nearest = std::min(nearest, (s - Eigen::Vector2d(x, y)).norm());
        }
        worst = std::max(worst, nearest);
      }
    }
    return worst;
  };
  EXPECT_LT(reach(dense), 2.3);
  EXPECT_GT(reach(sparse), 2.8);
  // The planned survey walks those stops.
  config.num_frames = framesToWalk(dense, config);
  const std::vector<StampedPose> poses = planSurvey(hall, config, 3);
  for (const Eigen::Vector2d& s : dense.stops) {
    double nearest = 1e9;
    for (const StampedPose& p : poses) {
      nearest = std::min(nearest, (p.T_W_C.translation().head<2>() - s).norm());
    }
    EXPECT_LT(nearest, 0.6) << s.transpose();  // smoothing rounds a stop off
  }
  // A room of the size the defaults were set on keeps num_waypoints.
  EXPECT_EQ(planSurveyPath(bathroom(8.0f, 7.0f), config, 3).stops.size(), 10u);
  config.area_per_stop_m2 = -1.0;
  EXPECT_THROW(config.check(), Error);
}

TEST(Survey, ANarrowWayToAStopIsWalkedCloserToItsSides) {
  // Two 3 x 3 m rooms joined by a 0.6 m gap in the wall between them at x = 3: at 0.3 m from
  // every surface the gap is shut (0.3 m and a cell on each side).
  const Eigen::Vector3f x = Eigen::Vector3f::UnitX(), y = Eigen::Vector3f::UnitY(),
                        z = Eigen::Vector3f::UnitZ();
  LabelledMesh mesh;
  addRect(&mesh, Eigen::Vector3f::Zero(), 6.0f * x, 3.0f * y, 2, 2);  // floor
  addRect(&mesh, Eigen::Vector3f::Zero(), 6.0f * x, 2.5f * z, 1, 1);
  addRect(&mesh, 3.0f * y, 6.0f * x, 2.5f * z, 1, 1);
  addRect(&mesh, Eigen::Vector3f::Zero(), 3.0f * y, 2.5f * z, 1, 1);
  addRect(&mesh, 6.0f * x, 3.0f * y, 2.5f * z, 1, 1);
  addRect(&mesh, 3.0f * x, 1.275f * y, 2.5f * z, 1, 1);               // wall, south part
  addRect(&mesh, 3.0f * x + 1.725f * y, 1.275f * y, 2.5f * z, 1, 1);  // wall, north part
  SurveyConfig config;
  config.num_frames = 0;  // one pass
  config.rate_hz = 5.0;
  const std::vector<Eigen::Vector2d> stops = {{1.5, 1.5}, {4.5, 1.5}};
  const SurveyPath path = planSurveyPathThrough(mesh, config, stops);
  EXPECT_LT(path.clearance_m, config.clearance_m);
  EXPECT_GE(path.clearance_m, config.min_clearance_m);
  const std::vector<StampedPose> poses = planSurveyThrough(mesh, config, stops, 1);
  ASSERT_GT(poses.size(), 10u);
  double east = 0.0;
  for (const StampedPose& p : poses) east = std::max(east, p.T_W_C.translation().x());
  EXPECT_GT(east, 4.0);  // through the gap into the east room
  EXPECT_GE(exactClearance(poses, mesh), path.clearance_m);
  // Without a lower clearance a stop in the room the walk cannot reach is a clear error, as
  // before.
  config.min_clearance_m = config.clearance_m;
  try {
    planSurveyThrough(mesh, config, stops, 1);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not within 0.5 m of floor"), std::string::npos)
        << e.what();
  }
}

TEST(Survey, TumRoundTrip) {
  test::TempDir dir;
  std::vector<StampedPose> traj(3);
  for (int k = 0; k < 3; ++k) {
    traj[k].utime = 1000000 + 33333 * k;
    traj[k].T_W_C.linear() =
        Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d(1, 2, 2).normalized()).toRotationMatrix();
    traj[k].T_W_C.translation() << 0.5 * k, -1.25, 2.0;
  }
  writeTumTrajectory(dir.path("t.txt"), traj);
  const auto back = readTumTrajectory(dir.path("t.txt"));
  ASSERT_EQ(back.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(back[k].utime, traj[k].utime);
    EXPECT_LT((back[k].T_W_C.matrix() - traj[k].T_W_C.matrix()).cwiseAbs().maxCoeff(), 1e-8);
  }
  std::ofstream(dir.path("bad.txt")) << "0 1 2 3 0 0 0 1\n1 2 3 nan 0 0 0 1\n";
  EXPECT_THROW(readTumTrajectory(dir.path("bad.txt")), Error);
}

// The line and what is wrong with it, for each kind of bad line; comments and blank lines are
// skipped and the line numbers count them.
TEST(Survey, TumReaderNamesTheBadLine) {
  test::TempDir dir;
  auto message = [&](const std::string& text) {
    std::ofstream(dir.path("t.txt")) << text;
    try {
      readTumTrajectory(dir.path("t.txt"));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string path = dir.path("t.txt");
  EXPECT_EQ(message("# header\n\n0.5 1 2 3 0 0 0 1\n1 2 3 nan 0 0 0 1\n"),
            path + ":4: non-finite pose");
  EXPECT_EQ(message("0.5 1 2 3 0 0 1\n"), path + ":1: expected 't tx ty tz qx qy qz qw'");
  EXPECT_EQ(message("0.5 1 2 3 0 0 0 2\n"), path + ":1: quaternion is not unit length");
  EXPECT_EQ(message("0.5 1 2 x 0 0 0 1\n"), path + ":1: 'x' is not a number");
  // A spreadsheet's export and a header line without '#' are named as such.
  EXPECT_EQ(message("0.5,1,2,3,0,0,0,1\n"),
            path +
                ":1: '0.5,1,2,3,0,0,0,1' is not a number (values separated by commas: panmap reads "
                "them separated by spaces or tabs)");
  EXPECT_EQ(message("timestamp tx ty tz qx qy qz qw\n0.5 1 2 3 0 0 0 1\n"),
            path + ":1: 'timestamp' is not a number (a header line? start it with '#')");
  EXPECT_EQ(message("# only a comment\n"), "trajectory " + path + " has no poses");
  EXPECT_EQ(message("0.5 1 2 3 0 0 0 1\n"), "no error");
  EXPECT_EQ(readTumTrajectory(path)[0].utime, 500000);
  EXPECT_THROW(readTumTrajectory(dir.path("missing.txt")), Error);
  // A time column in nanoseconds (EuRoC, ROS) overflowed the utime; it is read as such.
  EXPECT_EQ(message("1403636579763555584 1 2 3 0 0 0 1\n"), "no error");
  EXPECT_EQ(readTumTrajectory(path)[0].utime, 1403636579763556);
  EXPECT_EQ(message("1e30 1 2 3 0 0 0 1\n"),
            path + ":1: timestamp 1e+21 s is not a time a clock gives");
}

}  // namespace
}  // namespace panmap
