// The depth calibration model, its file, and learning a known distortion from rendered frames.
#include <cmath>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>

#include "panmap/calibration/depth_calibration.h"
#include "panmap/calibration/depth_calibrator.h"
#include "panmap/core/error.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/trajectory.h"
#include "test_helpers.h"
#include "test_meshes.h"

namespace panmap {
namespace {

// A 4x2 image of 2x1 cells (centres at u = 1 and u = 3), knots at 0 and 1 m:
// knot 0 = {a, b}, knot 1 = {c, d}.
DepthCalibration tiny(float a, float b, float c, float d) {
  return DepthCalibration(4, 2, 2, 1, 2, 1.0, {a, b, c, d});
}

TEST(DepthCalibration, OffsetInterpolatesBetweenCellCentresAndKnots) {
  const DepthCalibration k = tiny(0.01f, 0.03f, 0.05f, -0.01f);
  EXPECT_NEAR(k.offsetM(1.0, 0.5, 0.0), 0.01, 1e-7);   // a cell centre, knot 0
  EXPECT_NEAR(k.offsetM(3.0, 0.5, 0.0), 0.03, 1e-7);   // the other centre
  EXPECT_NEAR(k.offsetM(2.0, 0.5, 0.0), 0.02, 1e-7);   // half way
  EXPECT_NEAR(k.offsetM(0.0, 1.9, 0.0), 0.01, 1e-7);   // beyond the outer centres: held
  EXPECT_NEAR(k.offsetM(1.0, 0.5, 0.5), 0.03, 1e-7);   // half way between the knots
  EXPECT_NEAR(k.offsetM(3.0, 0.5, 7.0), -0.01, 1e-7);  // beyond the last knot: held
  EXPECT_NEAR(k.offsetM(2.0, 0.5, 0.25), 0.75 * 0.02 + 0.25 * 0.02, 1e-7);
  EXPECT_NEAR(k.rmsOffsetM(), std::sqrt((1.0 + 9.0 + 25.0 + 1.0) / 4.0) * 0.01, 1e-7);
  EXPECT_EQ(DepthCalibration().offsetM(1.0, 1.0, 1.0), 0.0);
}

TEST(DepthCalibration, ApplyCorrectsReadingsAndKeepsHoles) {
  const DepthCalibration k = tiny(0.0123f, 0.0123f, 0.0123f, -2.0f);
  DepthImage raw(4, 2);
  raw(1, 0) = 1000;  // 1 m at the first centre: + 12.3 mm
  raw(3, 1) = 1000;  // + 2 m at knot 1 would be fine, -2 m is not a depth: clamped to 1 unit
  DepthImage out;
  k.apply(raw, 0.001, &out);
  EXPECT_EQ(out(1, 0), 1012);
  EXPECT_EQ(out(3, 1), 1);
  EXPECT_EQ(out(0, 0), 0);  // no reading stays none
  ThreadPool pool(2);       // rows shared among threads: the same image
  DepthImage shared;
  k.apply(raw, 0.001, &shared, &pool);
  EXPECT_EQ(shared.pixels(), out.pixels());
  for (int v = 0; v < raw.height(); ++v) {  // one reading at a time: the same bits
    for (int u = 0; u < raw.width(); ++u) {
      EXPECT_EQ(k.correctedReading(u, v, raw(u, v), 0.001), out(u, v)) << u << " " << v;
    }
  }
  DepthImage wrong(5, 2);
  test::expectError([&] { k.apply(wrong, 0.001, &out); }, {"depth calibration is for 4x2"});
  DepthCalibration().apply(wrong, 0.001, &out);  // the identity fits any size
  EXPECT_EQ(out.width(), 5);
}

TEST(DepthCalibration, BadGridsAreRefused) {
  test::expectError(
      [] {
        DepthCalibration(4, 2, 2, 1, 2, 1.0, {0, 0, 0});
      },
      {"3 offsets for 4 grid values"});
  test::expectError([] { DepthCalibration(4, 2, 2, 1, 2, 1.0, {0, 0, 0, NAN}); }, {"non-finite"});
  test::expectError([] { DepthCalibration(4, 2, 2, 1, 2, 0.0, {0, 0, 0, 0}); }, {"knot spacing"});
  test::expectError([] { DepthCalibration(4, 2, 8, 1, 2, 1.0, std::vector<float>(16)); },
                    {"cells"});
}

TEST(DepthCalibration, FilesRoundTripAndBadFilesAreNamed) {
  test::TempDir dir;
  const DepthCalibration k = tiny(quantiseOffsetM(0.01234), quantiseOffsetM(-0.0071),
                                  quantiseOffsetM(0.0), quantiseOffsetM(0.0305));
  const std::string path = dir.path("sensor.json");
  k.save(path);
  EXPECT_EQ(DepthCalibration::load(path), k);
  EXPECT_NEAR(DepthCalibration::load(path).offsetsM()[0], 0.0123, 1e-7);

  test::expectError([&] { DepthCalibration::load(dir.path("missing.json")); },
                    {"missing.json: cannot open"});
  auto writeText = [&](const std::string& text) {
    std::ofstream(dir.path("bad.json")) << text;
    return dir.path("bad.json");
  };
  test::expectError([&] { DepthCalibration::load(writeText("{\"format\": \"panmap-depth-cal")); },
                    {"bad.json"});
  test::expectError([&] { DepthCalibration::load(writeText("{\"format\": \"other\"}")); },
                    {"not a panmap depth calibration"});
  test::expectError(
      [&] {
        DepthCalibration::load(writeText(
            "{\"format\": \"panmap-depth-calibration\", \"version\": 1, \"width\": 4, "
            "\"height\": 2, \"cells_x\": 2, \"cells_y\": 1, \"knots\": 2, \"knot_spacing_m\": 1, "
            "\"offsets_mm\": [[1, 2], [3]]}"));
      },
      {"cells_x * cells_y values"});
  test::expectError([&] { DepthCalibration().save(dir.path("empty.json")); }, {"empty"});
}

// Procedural room 1 seen from 40 poses of its survey, with exact depth.
struct RoomViews {
  RoomViews() : room(generateRoom(1)), renderer(room.mesh) {
    SurveyConfig survey;
    survey.num_frames = 200;
    const std::vector<StampedPose> trajectory = planSurvey(room.mesh, survey, 1);
    DepthNoiseConfig exact;
    exact.enabled = false;
    for (size_t k = 0; k < trajectory.size(); k += 5) {
      CalibrationFrame f;
      f.camera = test::kinectCamera();
      f.T_W_C = trajectory[k].T_W_C;
      f.depth = simulateDepth(renderer.render(f.camera, f.T_W_C), exact, 0);
      frames.push_back(std::move(f));
    }
  }
  ProceduralRoom room;
  MeshRenderer renderer;
  std::vector<CalibrationFrame> frames;
};

DepthCalibrator::Config coarse() {
  DepthCalibrator::Config c;
  c.cells_x = 8;
  c.cells_y = 6;
  c.knots = 9;
  c.knot_spacing_m = 0.5;
  c.voxel_size_m = 0.02f;
  c.pixel_stride = 4;
  return c;
}

// A smooth pattern of a few millimetres, bending depth more with distance, with no mean at any
// knot (what the calibrator can observe).
DepthCalibration knownPattern(int width, int height) {
  const DepthCalibrator::Config c = coarse();
  std::vector<float> offsets;
  for (int k = 0; k < c.knots; ++k) {
    for (int y = 0; y < c.cells_y; ++y) {
      for (int x = 0; x < c.cells_x; ++x) {
        const double pattern = std::sin(2.0 * M_PI * (x + 0.5) / c.cells_x) +
                               0.5 * std::cos(2.0 * M_PI * (y + 0.5) / c.cells_y);
        offsets.push_back(static_cast<float>(0.004 * pattern * (k * c.knot_spacing_m / 2.0)));
      }
    }
  }
  return DepthCalibration(width, height, c.cells_x, c.cells_y, c.knots, c.knot_spacing_m, offsets);
}

// Correlation (about 0) of two calibrations' grid values at the knots the frames reach (1-3 m).
double correlation(const DepthCalibration& a, const DepthCalibration& b) {
  const size_t layer = static_cast<size_t>(a.cellsX()) * a.cellsY();
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (size_t i = 2 * layer; i < 7 * layer; ++i) {
    ab += static_cast<double>(a.offsetsM()[i]) * b.offsetsM()[i];
    aa += static_cast<double>(a.offsetsM()[i]) * a.offsetsM()[i];
    bb += static_cast<double>(b.offsetsM()[i]) * b.offsetsM()[i];
  }
  return ab / std::sqrt(aa * bb);
}

TEST(DepthCalibrator, LearnsAKnownDistortionAndInventsNoneOnExactDepth) {
  static const RoomViews* views = new RoomViews();
  const PinholeCamera camera = test::kinectCamera();
  const DepthCalibration truth = knownPattern(camera.width, camera.height);
  // The sensor reads depth short by the pattern: the calibration must add it back.
  std::vector<CalibrationFrame> distorted = views->frames;
  for (CalibrationFrame& f : distorted) {
    for (int v = 0; v < camera.height; ++v) {
      for (int u = 0; u < camera.width; ++u) {
        const uint16_t d = f.depth(u, v);
        if (d == 0) continue;
        f.depth(u, v) =
            static_cast<uint16_t>(std::lround(d - 1000.0 * truth.offsetM(u, v, d * 1e-3)));
      }
    }
  }
  ThreadPool pool(2);
  const DepthCalibrator calibrator(coarse());
  std::vector<CalibrationPass> passes;
  const DepthCalibration learnt = calibrator.calibrate(distorted, &pool, &passes);
  ASSERT_EQ(passes.size(), 6u);
  // Where the frames see a surface from one side of the image only, a calibration error that
  // every view of it shares leaves no disagreement: the survey does not pin every grid value,
  // so the learnt pattern follows the truth closely but not exactly.
  EXPECT_GT(correlation(learnt, truth), 0.7);
  // The frames agree with their map much better than before.
  EXPECT_LT(passes.back().rms_residual_m, 0.6 * passes.front().rms_residual_m);
  EXPECT_GT(passes.front().rms_residual_m, 0.003);

  // Exact depth: nothing to learn beyond the depth unit's rounding.
  const DepthCalibration none = calibrator.calibrate(views->frames, &pool);
  EXPECT_LT(none.rmsOffsetM(), 0.0005);

  // The same on one thread, bit for bit.
  ThreadPool one(1);
  EXPECT_EQ(calibrator.calibrate(distorted, &one), learnt);
}

TEST(DepthCalibrator, RefusesWhatItCannotLearnFrom) {
  ThreadPool pool(1);
  const DepthCalibrator calibrator(coarse());
  test::expectError([&] { calibrator.calibrate({}, &pool); }, {"at least one frame"});
  CalibrationFrame a, b;
  a.camera = test::kinectCamera();
  a.depth = DepthImage(a.camera.width, a.camera.height);
  b = a;
  b.camera = a.camera.resized(320, 240);
  b.depth = DepthImage(320, 240);
  test::expectError([&] { calibrator.calibrate({a, b}, &pool); }, {"must all be 640x480"});
  test::expectError([&] { calibrator.calibrate({a}, &pool); }, {"no depth point"});
  DepthCalibrator::Config bad = coarse();
  bad.passes = 0;
  test::expectError([&] { DepthCalibrator{bad}; }, {"passes"});
}

}  // namespace
}  // namespace panmap
