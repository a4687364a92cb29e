#include "panmap/io/dataset_reader.h"

#include <cmath>
#include <filesystem>
#include <regex>
#include <sstream>

#include "panmap/core/error.h"
#include "panmap/io/internal/readers.h"
#include "panmap/io/text_files.h"

namespace panmap {

void DatasetOptions::check() const {
  if (!(frame_rate_hz > 0.0 && std::isfinite(frame_rate_hz))) {
    throw Error("frame rate must be positive");
  }
  if (!(tum_max_dt_s > 0.0)) throw Error("TUM association tolerance must be positive");
  if (!(pose_tolerance > 0.0)) throw Error("pose tolerance must be positive");
  if (intrinsics &&
      !((*intrinsics)(0) > 0.0 && (*intrinsics)(1) > 0.0 && intrinsics->allFinite())) {
    throw Error("intrinsics must be fx,fy,cx,cy with positive focal lengths");
  }
}

const char* datasetLayoutName(DatasetLayout layout) {
  switch (layout) {
    case DatasetLayout::kSevenScenes:
      return "7scenes";
    case DatasetLayout::kScanNet:
      return "scannet";
    case DatasetLayout::kTum:
      return "tum";
    default:
      return "auto";
  }
}

DatasetLayout parseDatasetLayout(const std::string& name) {
  for (DatasetLayout layout : {DatasetLayout::kAuto, DatasetLayout::kSevenScenes,
                               DatasetLayout::kScanNet, DatasetLayout::kTum}) {
    if (name == datasetLayoutName(layout)) return layout;
  }
  throw Error("unknown dataset layout '" + name + "' (auto, 7scenes, scannet, tum)");
}

std::unique_ptr<DatasetReader> openDataset(const std::string& directory,
                                           const DatasetOptions& options) {
  options.check();
  if (!isDirectory(directory)) throw Error("dataset folder " + directory + " does not exist");
  DatasetLayout layout = options.layout;
  if (layout == DatasetLayout::kAuto) {
    namespace fs = std::filesystem;
    if (isRegularFile(directory + "/depth.txt") && isRegularFile(directory + "/rgb.txt")) {
      layout = DatasetLayout::kTum;
    } else if (isDirectory(directory + "/depth") && isDirectory(directory + "/color")) {
      layout = DatasetLayout::kScanNet;
    } else {
      layout = DatasetLayout::kSevenScenes;  // its constructor says so if no frame is found
    }
  }
  switch (layout) {
    case DatasetLayout::kScanNet:
      return internal::makeScanNetReader(directory, options);
    case DatasetLayout::kTum:
      return internal::makeTumReader(directory, options);
    default:
      return internal::makeSevenScenesReader(directory, options);
  }
}

LabelImage registerLabelsToDepth(const LabelImage& labels_color, const DatasetFrame& frame,
                                 const std::string& what) {
  const int src_w = frame.color_source_width;
  const int src_h = frame.color_source_height;
  if (labels_color.width() != src_w || labels_color.height() != src_h) {
    std::ostringstream msg;
    msg << what << ": mask is " << labels_color.width() << "x" << labels_color.height()
        << " but its colour image is " << src_w << "x" << src_h;
    throw Error(msg.str());
  }
  if (frame.color_map_u.empty()) return labels_color;
  const auto& mu = frame.color_map_u;
  const auto& mv = frame.color_map_v;
  LabelImage out(mu.width(), mu.height(), 0);
  for (int v = 0; v < out.height(); ++v) {
    for (int u = 0; u < out.width(); ++u) {
      const int uc = static_cast<int>(std::lround(mu(u, v)));
      const int vc = static_cast<int>(std::lround(mv(u, v)));
      if (uc >= 0 && vc >= 0 && uc < src_w && vc < src_h) out(u, v) = labels_color(uc, vc);
    }
  }
  return out;
}

namespace internal {

std::optional<Eigen::Isometry3d> readPoseFile(const std::string& path, double tolerance,
                                              std::string* problem) {
  if (!isRegularFile(path)) {
    *problem = path + ": pose file missing";
    return std::nullopt;
  }
  const Eigen::Matrix4d T = readMatrixFile(path, 4, 4);
  std::string why;
  if (!isRigidTransform(T, tolerance, &why)) {
    *problem = path + ": invalid pose, " + why;
    return std::nullopt;
  }
  return nearestIsometry(T);
}

std::vector<std::pair<long long, std::string>> listNumberedFiles(const std::string& dir,
                                                                 const std::string& pattern) {
  namespace fs = std::filesystem;
  const std::regex re(pattern);
  std::vector<std::pair<long long, std::string>> out;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    std::smatch m;
    if (std::regex_match(name, m, re)) out.emplace_back(std::stoll(m[1].str()), name);
  }
  if (ec) throw Error("cannot list " + dir + ": " + ec.message());
  std::sort(out.begin(), out.end());
  return out;
}

int64_t frameUtime(long long number, double rate_hz) {
  return static_cast<int64_t>(std::llround(static_cast<double>(number) * 1e6 / rate_hz));
}

std::string fileStem(const std::string& path) {
  return std::filesystem::path(path).stem().string();
}

void checkImageSize(const std::string& path, const char* kind, int width, int height,
                    int expected_width, int expected_height) {
  if (width == expected_width && height == expected_height) return;
  std::ostringstream msg;
  msg << path << ": " << kind << " image is " << width << "x" << height << ", expected "
      << expected_width << "x" << expected_height;
  throw Error(msg.str());
}

}  // namespace internal
}  // namespace panmap
