#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "panmap/calibration/depth_calibration.h"
#include "panmap/core/camera.h"
#include "panmap/core/frame.h"
#include "panmap/core/labelled_mesh.h"
#include "panmap/render/renderer.h"
#include "panmap/sim/depth_noise.h"
#include "panmap/sim/pose_drift.h"
#include "panmap/sim/segmenter_noise.h"
#include "panmap/sim/trajectory.h"

namespace panmap {

/// Everything that shapes a synthetic sequence besides the mesh and the trajectory.
struct SynthConfig {
  PinholeCamera camera{525.0, 525.0, 319.5, 239.5, 640, 480};  ///< Kinect-like depth camera
  double depth_scale_m = 0.001;  ///< depth units of the output (millimetres)
  RenderConfig render;
  DepthNoiseConfig depth;
  /// A fixed-pattern depth error added to every frame's noisy depth, as a real sensor's pattern
  /// moves with the camera (sensorDepthPattern() makes one from a real sensor's calibration);
  /// empty: none. Its image size must be the camera's.
  DepthCalibration depth_pattern;
  SegmenterNoiseConfig masks = SegmenterNoiseConfig::fromPreset("m2f");
  PoseDriftConfig poses = PoseDriftConfig::fromPreset("slam");
  int min_view_px = 200;            ///< an instance counts as seen in a frame from this many pixels
  double distinct_view_deg = 20.0;  ///< viewing directions this far apart are distinct viewpoints
  uint64_t seed = 1;
  /// Throws Error naming the bad field.
  void check() const;
};

/// The same scene, sensor and segmenter seen at `scale` times the image size with the same field
/// of view: the camera's size and focal lengths times scale, every pixel length of the depth
/// and segmenter noise (edge jitter, outline displacement, its control grid, contact) times
/// scale and every pixel area (miss sizes, false positives, statistics, min_view_px) times
/// scale^2, so each error keeps its angular size (docs/SIMULATION.md, "Other image sizes").
/// Throws Error for a scale outside [0.25, 4] or with a depth pattern (made for one size).
SynthConfig scaledImage(SynthConfig config, double scale);

/// The fixed-pattern depth error of the sensor that `calibration` corrects, times `scale`: a
/// calibration's offsets are added to a reading to correct it, so the sensor's error is their
/// negative. For SynthConfig::depth_pattern. Throws Error on a non-finite or negative scale.
DepthCalibration sensorDepthPattern(const DepthCalibration& calibration, double scale);

/// How far a recorded depth may lie from the mesh rendered at its pose and still agree with it:
/// a real sensor's noise at a few metres, and a reconstruction's error, stay within it.
constexpr double kRecordingAgreementM = 0.05;

/// One synthetic frame: what the sensor, the segmenter and the SLAM system deliver, with the
/// ground truth beside it.
struct SynthFrame {
  RgbdFrame rgbd;          ///< noisy depth, rendered colour
  PanopticFrame panoptic;  ///< simulated segmenter output
  StampedPose gt_pose;     ///< true T_W_C
  StampedPose input_pose;  ///< T_W_C as the drifting SLAM system reports it
  LabelImage gt_instance;  ///< ground-truth instance image
};

/// How well a sequence observed the labelled objects.
struct CoverageStats {
  int thing_instances = 0;    ///< non-stuff instances in the mesh
  int seen_once = 0;          ///< seen in at least one frame (min_view_px)
  int seen_from_3_views = 0;  ///< seen from at least 3 distinct viewpoints
  /// seen_from_3_views / thing_instances.
  double fractionSeenFrom3Views() const {
    return thing_instances ? static_cast<double>(seen_from_3_views) / thing_instances : 0.0;
  }
};

/// Renders a labelled mesh along a trajectory into RGB-D frames, segmenter output and
/// drifting poses. Frames are produced in order; everything is deterministic for the seed.
class SequenceSynthesizer {
 public:
  /// @param T_W_C_gt the true camera trajectory (utime and pose per frame)
  SequenceSynthesizer(const LabelledMesh& mesh, std::vector<StampedPose> T_W_C_gt,
                      const SynthConfig& config);

  /// Number of frames.
  size_t size() const { return gt_.size(); }
  /// Renders frame k (call with k = 0, 1, 2, ... for the coverage and segmenter statistics).
  SynthFrame frame(size_t k);
  /// Frame k of a recording instead of a rendering (call in the same order as frame()): the
  /// recorded depth and colour as they are, no simulated sensor noise; the segmenter's masks
  /// from the mesh rendered at the ground-truth pose with the recording's camera. The mesh must
  /// be the recorded scene in the recording's world frame (a ScanNet scan and its
  /// reconstruction). Throws Error when the recorded frame has no depth image.
  SynthFrame frameFromRecording(size_t k, RgbdFrame recorded);
  /// Ground-truth trajectory.
  const std::vector<StampedPose>& groundTruthTrajectory() const { return gt_; }
  /// Trajectory as the simulated SLAM system reports it.
  const std::vector<StampedPose>& inputTrajectory() const { return input_; }
  /// Coverage over the frames rendered so far.
  CoverageStats coverage() const;
  /// Of the pixels of the recorded frames so far that have depth where the mesh rendered at
  /// their pose has a surface, the share within kRecordingAgreementM of it (0 without any):
  /// well below 1, the mesh is not the recorded scene, or not in the recording's frame.
  double recordingDepthAgreement() const;
  /// Segmenter error statistics over the frames rendered so far.
  const SegmenterNoiseStats& segmenterStats() const { return segmenter_.stats(); }
  /// Per-instance facts the segmenter uses (class, extent, stuff).
  const std::map<int32_t, InstanceInfo>& instances() const { return infos_; }

 private:
  /// The segmenter's output and the coverage count of the view just rendered, around `rgbd`.
  SynthFrame finishFrame(size_t k, RgbdFrame rgbd);

  SynthConfig config_;
  MeshRenderer renderer_;
  SegmenterNoise segmenter_;
  std::vector<StampedPose> gt_;
  std::vector<StampedPose> input_;
  std::map<int32_t, InstanceInfo> infos_;
  std::map<int32_t, Eigen::Vector3d> centroids_;
  std::map<int32_t, std::vector<Eigen::Vector3d>> views_;  // distinct view directions seen
  size_t recorded_compared_px_ = 0;                        // recorded depth over a rendered surface
  size_t recorded_agreeing_px_ = 0;                        // of those, within kRecordingAgreementM
  RenderedView view_;
};

}  // namespace panmap
