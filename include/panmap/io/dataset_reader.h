#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/frame.h"
#include "panmap/core/pose.h"

namespace panmap {

/// One frame read from a dataset folder, colour already registered to the depth camera.
struct DatasetFrame {
  RgbdFrame rgbd;  ///< decoded images, intrinsics, utime, frame id
  /// The source's colour file bytes when they can travel unchanged (JPEG, not resampled).
  std::vector<uint8_t> color_jpeg;
  /// The source's depth file bytes when they can travel unchanged (16-bit PNG).
  std::vector<uint8_t> depth_png;
  /// T_W_C when the dataset has a valid pose for this frame.
  std::optional<Eigen::Isometry3d> T_W_C;
  std::string pose_problem;    ///< why T_W_C is empty (file and reason)
  std::string color_stem;      ///< colour file name without extension: the key of its masks
  int color_source_width = 0;  ///< colour image size in the dataset, before registration
  int color_source_height = 0;
  /// Per depth pixel, the colour-image pixel it sees (empty when colour is already registered).
  Image<float> color_map_u;
  Image<float> color_map_v;
};

/// A frame's time and pose, read without its images (DatasetReader::pose).
struct DatasetPose {
  int64_t utime = 0;
  int64_t frame_id = 0;
  std::optional<Eigen::Isometry3d> T_W_C;  ///< as DatasetFrame::T_W_C
  std::string problem;                     ///< as DatasetFrame::pose_problem
};

/// Which folder layout a dataset has. kFolder is the generic export: rgb/ (or color/) and
/// depth/ image folders, an intrinsics file and a pose file or folder. kScanNetSens is a
/// ScanNet .sens recording, read without exporting it.
enum class DatasetLayout { kAuto, kSevenScenes, kScanNet, kTum, kFolder, kScanNetSens };

/// How the folder layout pairs colour with depth images.
enum class FramePairing {
  kAuto,  ///< by name when the names agree, by position when the counts do, else by time
  kName,  ///< same frame number (or stem), else the same position in sorted order
  kTime,  ///< names are timestamps in seconds; nearest colour within tum_max_dt_s
};

/// How ScanNet colour is registered to the depth camera.
enum class ColorRegistration {
  kReproject,  ///< per pixel through depth and the colour-to-depth extrinsics
  kResize,     ///< resize the colour image to the depth size (common practice, ignores baseline)
};

/// Reader options; defaults suit the datasets' documented conventions.
struct DatasetOptions {
  DatasetLayout layout = DatasetLayout::kAuto;
  /// Replaces the dataset's intrinsics (fx, fy, cx, cy of the depth camera) when set.
  std::optional<Eigen::Vector4d> intrinsics;
  double frame_rate_hz = 30.0;  ///< time base for datasets without timestamps
  ColorRegistration registration = ColorRegistration::kReproject;
  double tum_max_dt_s = 0.02;  ///< TUM: max |t_rgb - t_depth| and |t_pose - t_depth|
  /// Timed poses: a frame between two poses at most this far apart takes their interpolation
  /// (a SLAM system's keyframes; the mapper's sync.max_pose_gap_ms is the same 200 ms).
  double max_pose_gap_s = 0.2;
  /// Largest |R^T R - I| entry accepted in a pose file (datasets store rounded matrices).
  double pose_tolerance = 1e-3;
  /// Metres per depth unit, replacing the layout's convention (7-Scenes and ScanNet mm, TUM
  /// 1/5000 m; the folder layout detects mm or 1/5000 m from the values when unset).
  std::optional<double> depth_scale_m;
  /// Intrinsics file (3x3 or 4x4 matrix, or fx fy cx cy) replacing the dataset's; ignored when
  /// `intrinsics` is set.
  std::string intrinsics_file;
  /// Folder and TUM layouts: the poses, a trajectory file (TUM, a matrix per line, stacked
  /// 4x4) or a folder of per-frame 4x4 files, instead of the one found in the folder.
  std::string poses_path;
  FramePairing pairing = FramePairing::kAuto;  ///< folder layout only
  /// Throws Error naming the bad option.
  void check() const;
};

/// A dataset folder as a sequence of frames.
class DatasetReader {
 public:
  virtual ~DatasetReader() = default;
  /// Short layout name: "7scenes", "scannet", "scannet-sens", "tum" or "folder".
  virtual std::string layoutName() const = 0;
  /// Number of frames (depth images) found.
  virtual size_t size() const = 0;
  /// Reads frame i (0-based, in time order). Throws Error naming the file at fault.
  virtual DatasetFrame read(size_t index) const = 0;
  /// Frame i's utime, id and pose as read(i) gives them, without decoding its images where
  /// the layout allows (ScanNet's); the default reads the frame. Throws Error as read() does.
  virtual DatasetPose pose(size_t index) const;
  /// Where the dataset's poses come from.
  virtual PoseSource poseSource() const { return PoseSource::kGroundTruth; }
  /// True when invalid poses are a documented property of the layout (ScanNet writes -inf
  /// rows for frames its reconstruction lost), so skipping them is the default.
  virtual bool invalidPosesExpected() const { return false; }
  /// True when the poses come from quaternions (a TUM-style file): their order may be w x y z.
  virtual bool posesAreQuaternions() const { return false; }
  /// Frames the reader dropped while indexing (e.g. TUM depth without a matching colour).
  virtual size_t unmatchedFrames() const { return 0; }
  /// What the unmatchedFrames() were, for "dropped N <what>".
  virtual std::string unmatchedWhat() const {
    return "depth images without a colour image in time";
  }
  /// What auto-detection chose, one line each (files found, depth scale, pairing), for users.
  virtual std::vector<std::string> notes() const { return {}; }
};

/// Opens a dataset folder, or a ScanNet .sens file (a folder holding exactly one, such as a
/// scan's folder from ScanNet's download script, opens it when no other layout matches).
/// Throws Error naming the folder or file when it is missing or does not look like the
/// layout; with kAuto and no layout recognised, the error lists every layout tried and what
/// each one missed.
std::unique_ptr<DatasetReader> openDataset(const std::string& directory,
                                           const DatasetOptions& options);

/// Brings a label image at the colour image's resolution into the depth camera (nearest
/// neighbour through the frame's colour map). Throws Error when sizes disagree.
LabelImage registerLabelsToDepth(const LabelImage& labels_color, const DatasetFrame& frame,
                                 const std::string& what);

/// Name of a layout.
const char* datasetLayoutName(DatasetLayout layout);

/// Parses "auto", "7scenes", "scannet", "scannet-sens", "tum" or "folder"; throws Error
/// otherwise.
DatasetLayout parseDatasetLayout(const std::string& name);

}  // namespace panmap
