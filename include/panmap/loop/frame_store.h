#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/camera.h"
#include "panmap/core/frame.h"
#include "panmap/core/image.h"
#include "panmap/core/pose.h"
#include "panmap/segmentation/panoptic_geometric.h"

namespace panmap {

/// Where and what the frame store keeps (docs/LOOP_CLOSURE.md, repair step 1).
struct FrameStoreConfig {
  /// Folder of the store (created when missing); empty: no store (off).
  std::string folder;
  /// Keep each frame's colour as a JPEG. Off by default: the repair re-integrates geometry and
  /// labels, colour is cosmetic and costs bytes on every frame.
  bool store_color = false;
  /// JPEG quality of the stored colour, 1..100 (only with store_color).
  int color_quality = 50;
  /// zstd level of the depth and label planes, 1..19 (lossless at every level; decoding speed
  /// does not depend on it). 5 keeps a 7-Scenes frame within the 150 kB budget
  /// (docs/LOOP_CLOSURE.md, panmap-bench-frame-store).
  int compression_level = 5;
  /// Throws Error naming the bad field.
  void check() const;
};

/// One frame as the store gives it back: exactly what was integrated, to re-integrate it at a
/// corrected pose.
struct StoredFrame {
  /// utime, camera (intrinsics), depth_scale_m, depth (as integrated, lossless) and colour
  /// (decoded JPEG, empty when not stored). frame_id and camera_name are not stored.
  RgbdFrame rgbd;
  /// T_W_C (camera to world, optical frame) the frame was last integrated with: the pose
  /// given to add(), or the latest updatePose(); exact to the last bit of each double.
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  /// Per pixel the super-point label it voted for (as assigned when integrated, merges not
  /// resolved), 0 = none; lossless for every int32.
  LabelImage labels;
  /// True when the frame's panoptic segmentation was stored with it (`panoptic` holds it):
  /// what a repair needs to associate the frame again at its corrected pose.
  bool has_panoptic = false;
  /// The frame's 2D panoptic segmentation (segment ids lossless for every int32, segments'
  /// scores exact), utime and frame_id set to the frame's utime and 0.
  PanopticFrame panoptic;
  /// The geometric segments it was mapped with and their config key, when they were stored
  /// with its segmentation (ids empty otherwise): mapping it again then skips the depth stages.
  GeometricSegments geometric;
};

/// The frames a map was built from, on disk, so that a loop closure can re-integrate them at
/// their corrected poses (docs/LOOP_CLOSURE.md).
///
/// Layout of the folder: `index.txt` (a version line, then one line per added frame and per
/// pose update, each ending in its CRC-32; a frame stored with its panoptic segmentation has a
/// `masks` line right after its frame line, appended with it) and `frames/<utime>.depth.zst`
/// (16-bit depth as integrated, a zstd plane of io/plane_codec.h), `.labels.zst` (int32
/// labels, a plane), `.color.jpg` (store_color only), and with a segmentation `.masks.zst`
/// (segment ids, a plane) and `.segments.txt` (one segment per line: id, category, source
/// category, thing 0/1, score); a frame stored with its geometric segments too has a `geometric`
/// line after its masks line (the segmentation config key, then the file) and
/// `.geometric.zst` (segment ids, a plane; version 2 stores only). Stores of version 1
/// (`panmap-frame-store 1`) keep depth as a 16-bit PNG and labels and masks as COCO panoptic RGB
/// PNGs (bits 0-23) with a second PNG for bits 24-31 when some id needs them (`.labels-hi.png`,
/// `.masks-hi.png`); they are read and grow in their own format. Each file is written atomically
/// (AtomicFileWriter) before the frame's index line is appended and synced, so a crash at any
/// moment leaves whole frames, a frame missing from the index, or a cut last index line, which
/// reopening names and drops.
///
/// Thread-safety: every member function may be called from several threads at once. A mutex
/// guards the index; encoding, decoding and file writes run outside it, so add() and load()
/// of different frames overlap.
class FrameStore {
 public:
  /// How much of each frame reopening checks.
  enum class Check {
    kSizes,     ///< every file exists with the size the index gives (stat only)
    kContents,  ///< and its bytes have the CRC-32 the index gives (reads every file)
  };

  /// Opens the store in config.folder, creating the folder and an empty index when there is
  /// none, and reading the frames already there otherwise (as open() does, with kContents);
  /// added frames use this config's colour settings. Throws Error when the config is invalid,
  /// the folder is empty (store off) or cannot be created, or the index is not a frame store's.
  explicit FrameStore(const FrameStoreConfig& config);
  /// Closes the index.
  ~FrameStore();
  FrameStore(const FrameStore&) = delete;
  FrameStore& operator=(const FrameStore&) = delete;

  /// Reopens the store in `folder`: rebuilds the frame list from its index, checks each
  /// frame's files, and keeps every frame that passes. A frame whose files are missing, cut or
  /// corrupt, or whose index line is, is named in problems() and left out; a cut last index
  /// line (a crash while adding) is removed from the file. Throws Error naming the folder when
  /// there is no store there or its index is not a frame store's (version line).
  /// @param config_template colour settings for frames added after reopening (folder ignored)
  static std::unique_ptr<FrameStore> open(const std::string& folder, Check check = Check::kContents,
                                          const FrameStoreConfig& config_template = {});

  /// Stores one integrated frame. Throws Error, storing nothing, when the utime is already
  /// stored (a corrected pose goes through updatePose()), the camera is invalid, an image size
  /// differs from the camera's, depth_scale_m is not positive, the pose is not a finite rigid
  /// transform, or a file cannot be written.
  /// @param utime the frame's capture time, microseconds (its key in the store)
  /// @param T_W_C camera-to-world pose (optical frame) it was integrated with
  /// @param camera depth camera intrinsics it was integrated with
  /// @param depth_scale_m metres per depth unit
  /// @param depth depth image as integrated, in depth_scale_m units
  /// @param labels super-point label per pixel it voted for, 0 = none
  /// @param color registered colour, or null; stored only when config.store_color
  /// @param panoptic the segmentation the frame was mapped with, or null when it was mapped
  ///        without one (a repair then maps it again without); its segment image must have
  ///        the camera's size. A store holding any keeps every frame's (MapRepairConfig).
  /// @param geometric the geometric segments it was mapped with, or null; stored only with a
  ///        segmentation (a repair that maps the frame again takes them) and in version 2;
  ///        the camera's size
  void add(int64_t utime, const Eigen::Isometry3d& T_W_C, const PinholeCamera& camera,
           double depth_scale_m, const DepthImage& depth, const LabelImage& labels,
           const ColorImage* color = nullptr, const PanopticFrame* panoptic = nullptr,
           const GeometricSegments* geometric = nullptr);
  /// add() with the frame's utime, camera, depth scale, depth and colour (if any).
  /// @param T_W_C camera-to-world pose (optical frame) it was integrated with
  /// @param panoptic the frame's panoptic segmentation, or null
  /// @param geometric its geometric segments, or null
  void add(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C, const LabelImage& labels,
           const PanopticFrame* panoptic = nullptr, const GeometricSegments* geometric = nullptr);

  /// Records that a frame is now integrated at T_W_C (a repair moved it); durable on return.
  /// Throws Error naming the utime when it is not stored, or when the pose is not rigid.
  /// @param T_W_C camera-to-world pose (optical frame) of the re-integration
  void updatePose(int64_t utime, const Eigen::Isometry3d& T_W_C);
  /// Records that the repair of correction `correction_id` is in the map (after its pose
  /// lines); durable on return. A map loaded or resumed with this store refuses corrections
  /// no newer than it, as the session that applied it did: an older one would undo the repair.
  void recordCorrection(int64_t correction_id);
  /// The newest correction recorded (recordCorrection), or nullopt when none was.
  std::optional<int64_t> lastCorrectionId() const;

  /// What load() reads.
  enum class Parts {
    kAll,  ///< every file of the frame
    /// Depth, labels and colour: what a re-integration votes with. The segmentation and the
    /// geometric segments, a third of the decoding, stay on disk (has_panoptic false).
    kWithoutSegmentation,
  };

  /// Reads and decodes one frame. Throws Error naming the utime when it is not stored, and
  /// naming the file when one it reads is missing, corrupt or differs from its checksum.
  StoredFrame load(int64_t utime, Parts parts = Parts::kAll) const;

  /// Number of frames stored.
  size_t size() const;
  /// True when the frame of `utime` is stored.
  bool has(int64_t utime) const;
  /// Number of them stored with their panoptic segmentation.
  size_t sizeWithPanoptic() const;
  /// The stored frames' utimes, increasing.
  std::vector<int64_t> utimes() const;
  /// Each stored frame's current pose by utime, increasing (frame_id -1, source unknown): the
  /// trajectory applyCorrection() takes.
  std::vector<StampedPose> trajectory() const;
  /// Bytes of the stored frames' files plus the index.
  uint64_t bytesOnDisk() const;
  /// What opening found wrong, one line each (a frame left out, a cut or corrupt index line).
  std::vector<std::string> problems() const;
  /// Frames named in problems() and left out when opening.
  size_t skipped() const;
  /// The config in use.
  const FrameStoreConfig& config() const { return config_; }
  /// Format version of the store's files: 2 (zstd planes) for a new store, 1 (PNGs) for a
  /// store written before.
  int version() const { return version_; }

  /// Bytes of one frame's files, as add() wrote them (for measurements).
  struct FrameBytes {
    uint64_t depth = 0;
    uint64_t labels = 0;  ///< both label planes
    uint64_t color = 0;
    uint64_t masks = 0;      ///< segment id planes and segment list
    uint64_t geometric = 0;  ///< geometric segments plane
    uint64_t total() const { return depth + labels + color + masks + geometric; }
  };
  /// The file sizes of a stored frame; throws Error naming the utime when it is not stored.
  FrameBytes frameBytes(int64_t utime) const;

 private:
  /// A stored file: its bytes and CRC-32 (size 0: no file).
  struct FileRecord {
    uint64_t size = 0;
    uint32_t crc = 0;
  };
  /// Everything the index says about one frame.
  struct Entry {
    Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
    PinholeCamera camera;
    double depth_scale_m = 0.0;
    FileRecord depth, labels, labels_hi, color;
    FileRecord masks, masks_hi, segments;  ///< all size 0: no segmentation stored
    FileRecord geometric;                  ///< size 0: no geometric segments stored
    uint64_t geometric_key = 0;            ///< their DepthSegmentationConfig::key()
    uint64_t bytes() const {
      return depth.size + labels.size + labels_hi.size + color.size + masks.size + masks_hi.size +
             segments.size + geometric.size;
    }
  };

  FrameStore(const FrameStoreConfig& config, bool create, Check check);
  void readIndex(Check check);
  void appendIndexLine(const std::string& line);
  std::string framePath(int64_t utime, const char* suffix) const;
  std::string checkFiles(int64_t utime, const Entry& entry, Check check) const;

  FrameStoreConfig config_;
  std::string index_path_;
  int version_ = 2;           ///< format of the frames' files (index version line); set on opening
  mutable std::mutex mutex_;  ///< guards everything below
  int index_fd_ = -1;
  std::map<int64_t, Entry> entries_;
  std::set<int64_t> pending_;  ///< utimes being added (files written, index line not yet)
  uint64_t frame_bytes_ = 0;   ///< files of the entries
  uint64_t index_bytes_ = 0;
  std::vector<std::string> problems_;
  size_t skipped_ = 0;
  std::optional<int64_t> last_correction_id_;
};

}  // namespace panmap
