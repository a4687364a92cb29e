#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "panmap/io/dataset_reader.h"

namespace panmap {
namespace internal {

std::unique_ptr<DatasetReader> makeSevenScenesReader(const std::string& dir,
                                                     const DatasetOptions& options);
std::unique_ptr<DatasetReader> makeScanNetReader(const std::string& dir,
                                                 const DatasetOptions& options);
/// `path`: a ScanNet .sens file.
std::unique_ptr<DatasetReader> makeScanNetSensReader(const std::string& path,
                                                     const DatasetOptions& options);
std::unique_ptr<DatasetReader> makeTumReader(const std::string& dir, const DatasetOptions& options);
std::unique_ptr<DatasetReader> makeFolderReader(const std::string& dir,
                                                const DatasetOptions& options);

/// Why a folder is not of a layout ("" when it looks like one), checked without reading
/// images: the auto-detection and its error message.
std::string missingForSevenScenes(const std::string& dir);
std::string missingForScanNet(const std::string& dir);
/// The one *.sens file in `dir`: its path in *found and "", or why there is none to take.
std::string missingForScanNetSens(const std::string& dir, std::string* found = nullptr);
std::string missingForTum(const std::string& dir);
std::string missingForFolder(const std::string& dir);

/// The key = value lines of a ScanNet scene's metadata file (<scene>.txt), or none when the
/// file is missing or has no colorWidth and depthWidth.
std::map<std::string, std::string> readScanNetMetaFile(const std::string& path);

/// The metadata of the first .txt in `dir` that readScanNetMetaFile() takes (*path_out its
/// path), or none.
std::map<std::string, std::string> readScanNetSceneMeta(const std::string& dir,
                                                        std::string* path_out);

/// T_C_D (depth camera to colour camera) from the metadata's colorToDepthExtrinsics, or none
/// when it has none. Throws Error naming `meta_path` when the value is not a rigid transform.
std::optional<Eigen::Isometry3d> scanNetColorFromDepth(
    const std::map<std::string, std::string>& meta, const std::string& meta_path);

/// Colour-image coordinates of every pixel of a ScanNet depth image: kReproject moves each
/// depth pixel's point (at infinity without depth) into the colour camera by T_C_D and
/// projects it; kResize scales pixel centres.
void scanNetColorMap(const DepthImage& depth, const PinholeCamera& depth_camera,
                     const PinholeCamera& color_camera, const Eigen::Isometry3d& T_C_D,
                     double depth_scale_m, ColorRegistration registration, Image<float>* map_u,
                     Image<float>* map_v);

/// Colour-image coordinates of every depth pixel when the colour image is the depth image
/// resized (pixel centres scaled).
void resizeColorMap(int depth_width, int depth_height, int color_width, int color_height,
                    Image<float>* map_u, Image<float>* map_v);

/// Index of the time nearest to t in a sorted list, or -1 when none is within max_dt.
long nearestIndex(const std::vector<double>& sorted_times, double t, double max_dt);

/// Pose at time t_s from time-sorted samples: interpolated between the bracketing samples
/// when they are at most max(max_gap_s, 2 max_dt_s) apart, else the nearest within max_dt_s.
/// Sets `problem` (naming `source`) and returns nothing when no sample is close enough.
std::optional<Eigen::Isometry3d> poseAtTime(const std::vector<StampedPose>& sorted, double t_s,
                                            double max_dt_s, double max_gap_s,
                                            const std::string& source, std::string* problem);

/// Reads a 4x4 camera-to-world pose file. Sets `problem` (file and reason) and returns
/// nothing when the file is missing or the matrix is not a rigid transform.
std::optional<Eigen::Isometry3d> readPoseFile(const std::string& path, double tolerance,
                                              std::string* problem);

/// Regular files in a folder whose names match a regex; the first capture group must be a
/// frame number. Sorted by that number.
std::vector<std::pair<long long, std::string>> listNumberedFiles(const std::string& dir,
                                                                 const std::string& pattern);

/// Files in `dir` matching `pattern` (first capture group a frame number) whose number no
/// entry of `frames` has: e.g. colour images whose depth image is missing.
std::vector<std::string> unpairedFiles(const std::vector<std::pair<long long, std::string>>& frames,
                                       const std::string& dir, const std::string& pattern);

/// utime of frame `number` of a sequence recorded at rate_hz starting at utime 0.
int64_t frameUtime(long long number, double rate_hz);

/// The file name without folder and last extension.
std::string fileStem(const std::string& path);

/// Checks that a decoded image has the size the sequence expects; throws Error otherwise.
void checkImageSize(const std::string& path, const char* kind, int width, int height,
                    int expected_width, int expected_height);

/// Throws Error (naming `from`, the intrinsics' source) when the camera's principal point lies
/// outside the middle half of its image, as it does when images were resized after
/// calibration; the message gives the intrinsics scaled to the images when that fits.
void checkPrincipalPoint(const PinholeCamera& camera, const std::string& from);

/// Raw depth values of a few images spread over a sequence, as units (not metres): what a
/// reader judges a depth unit by.
struct DepthValueSample {
  size_t images = 0;         ///< images that held a valid pixel
  double median = 0.0;       ///< median of their valid pixels (every second row and column)
  double largest_p99 = 0.0;  ///< largest of the images' 99th percentiles
};

/// Samples up to `max_images` of the depth images at `paths`, spread evenly over them
/// (unreadable images are skipped: they are named when their frame is read).
DepthValueSample sampleDepthValues(const std::vector<std::string>& paths, size_t max_images = 9);

/// "0.001 m per unit (mm)", "1/5000 m per unit (TUM)" or "S m per unit".
std::string formatDepthScale(double scale);

/// Reads the depth PNG at path into frame->depth_png (its bytes) and frame->rgbd.depth; throws
/// Error naming the file when it cannot be read or decoded or is not width x height.
void readDepthPng(const std::string& path, int width, int height, DatasetFrame* frame);

/// Reads a colour image taken with the depth camera's size and viewpoint into
/// frame->rgbd.color, with color_stem, the source size, and color_jpeg when the file is a
/// complete JPEG (sent on as it is); throws Error naming the file like readDepthPng.
void readRegisteredColor(const std::string& path, int width, int height, DatasetFrame* frame);

}  // namespace internal
}  // namespace panmap
