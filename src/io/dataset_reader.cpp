#include "panmap/io/dataset_reader.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>
#include <set>
#include <sstream>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/internal/readers.h"
#include "panmap/io/text_files.h"

namespace panmap {

void DatasetOptions::check() const {
  if (!(frame_rate_hz > 0.0 && std::isfinite(frame_rate_hz))) {
    throw Error("frame rate must be positive");
  }
  if (!(tum_max_dt_s > 0.0)) throw Error("TUM association tolerance must be positive");
  if (!(max_pose_gap_s >= 0.0)) throw Error("max_pose_gap_s must be >= 0");
  if (!(pose_tolerance > 0.0)) throw Error("pose tolerance must be positive");
  if (intrinsics &&
      !((*intrinsics)(0) > 0.0 && (*intrinsics)(1) > 0.0 && intrinsics->allFinite())) {
    throw Error("intrinsics must be fx,fy,cx,cy with positive focal lengths");
  }
  if (depth_scale_m && !(*depth_scale_m > 0.0 && std::isfinite(*depth_scale_m))) {
    throw Error("depth scale must be a positive number of metres per unit");
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
    case DatasetLayout::kFolder:
      return "folder";
    case DatasetLayout::kScanNetSens:
      return "scannet-sens";
    default:
      return "auto";
  }
}

DatasetLayout parseDatasetLayout(const std::string& name) {
  for (DatasetLayout layout :
       {DatasetLayout::kAuto, DatasetLayout::kSevenScenes, DatasetLayout::kScanNet,
        DatasetLayout::kScanNetSens, DatasetLayout::kTum, DatasetLayout::kFolder}) {
    if (name == datasetLayoutName(layout)) return layout;
  }
  throw Error("unknown dataset layout '" + name +
              "' (auto, 7scenes, scannet, scannet-sens, tum, folder)");
}

std::unique_ptr<DatasetReader> openDataset(const std::string& directory,
                                           const DatasetOptions& given) {
  given.check();
  DatasetOptions options = given;
  if (!options.intrinsics && !options.intrinsics_file.empty()) {
    options.intrinsics = readIntrinsicsFile(options.intrinsics_file);
  }
  DatasetLayout layout = options.layout;
  const bool sens_file = isRegularFile(directory);
  if (sens_file) {
    if (layout != DatasetLayout::kAuto && layout != DatasetLayout::kScanNetSens) {
      throw Error(std::string("the ") + datasetLayoutName(layout) + " layout is a folder, " +
                  directory + " a file");
    }
    if (std::filesystem::path(directory).extension() != ".sens") {
      throw Error(directory + ": a dataset is a folder or a ScanNet .sens file");
    }
    layout = DatasetLayout::kScanNetSens;
  } else if (!isDirectory(directory)) {
    throw Error(std::filesystem::path(directory).extension() == ".sens"
                    ? "ScanNet recording " + directory + " does not exist"
                    : "dataset folder " + directory + " does not exist");
  }
  std::string sens_path = sens_file ? directory : "";
  if (layout == DatasetLayout::kAuto) {
    // Most specific first: ScanNet exports also have depth/ and color/ folders, and a scan's
    // folder with its .sens may hold an export of it too (the export is then read).
    const std::pair<DatasetLayout, std::string> tried[] = {
        {DatasetLayout::kTum, internal::missingForTum(directory)},
        {DatasetLayout::kScanNet, internal::missingForScanNet(directory)},
        {DatasetLayout::kSevenScenes, internal::missingForSevenScenes(directory)},
        {DatasetLayout::kFolder, internal::missingForFolder(directory)},
        {DatasetLayout::kScanNetSens, internal::missingForScanNetSens(directory, &sens_path)}};
    std::string why;
    for (const auto& [candidate, missing] : tried) {
      if (missing.empty()) {
        layout = candidate;
        break;
      }
      why += std::string(why.empty() ? "" : "; ") + datasetLayoutName(candidate) + ": " + missing;
    }
    if (layout == DatasetLayout::kAuto) {
      throw Error(directory + ": no known dataset layout (" + why + ")");
    }
  }
  if (!options.poses_path.empty() && layout != DatasetLayout::kFolder &&
      layout != DatasetLayout::kTum) {
    throw Error(std::string("--poses applies to the folder and tum layouts, not ") +
                datasetLayoutName(layout));
  }
  switch (layout) {
    case DatasetLayout::kScanNet:
      return internal::makeScanNetReader(directory, options);
    case DatasetLayout::kScanNetSens: {
      if (sens_path.empty()) {
        const std::string missing = internal::missingForScanNetSens(directory, &sens_path);
        if (!missing.empty()) throw Error(directory + ": " + missing);
      }
      return internal::makeScanNetSensReader(sens_path, options);
    }
    case DatasetLayout::kTum:
      return internal::makeTumReader(directory, options);
    case DatasetLayout::kFolder:
      return internal::makeFolderReader(directory, options);
    default:
      return internal::makeSevenScenesReader(directory, options);
  }
}

DatasetPose DatasetReader::pose(size_t index) const {
  const DatasetFrame frame = read(index);
  DatasetPose out;
  out.utime = frame.rgbd.utime;
  out.frame_id = frame.rgbd.frame_id;
  out.T_W_C = frame.T_W_C;
  out.problem = frame.pose_problem;
  return out;
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

std::string missingForSevenScenes(const std::string& dir) {
  return listNumberedFiles(dir, R"(frame-(\d+)\.depth\.png)").empty()
             ? "no frame-XXXXXX.depth.png files"
             : "";
}

std::string missingForScanNet(const std::string& dir) {
  for (const char* sub : {"depth", "color", "intrinsic"}) {
    if (!isDirectory(dir + "/" + sub)) return std::string("no ") + sub + "/ folder";
  }
  return "";
}

std::string missingForTum(const std::string& dir) {
  if (!isRegularFile(dir + "/depth.txt")) return "no depth.txt";
  if (!isRegularFile(dir + "/rgb.txt")) return "no rgb.txt";
  return "";
}

void resizeColorMap(int depth_width, int depth_height, int color_width, int color_height,
                    Image<float>* map_u, Image<float>* map_v) {
  *map_u = Image<float>(depth_width, depth_height);
  *map_v = Image<float>(depth_width, depth_height);
  const double sx = static_cast<double>(color_width) / depth_width;
  const double sy = static_cast<double>(color_height) / depth_height;
  for (int v = 0; v < depth_height; ++v) {
    for (int u = 0; u < depth_width; ++u) {
      (*map_u)(u, v) = static_cast<float>((u + 0.5) * sx - 0.5);
      (*map_v)(u, v) = static_cast<float>((v + 0.5) * sy - 0.5);
    }
  }
}

long nearestIndex(const std::vector<double>& sorted_times, double t, double max_dt) {
  const auto it = std::lower_bound(sorted_times.begin(), sorted_times.end(), t);
  long best = -1;
  double best_dt = max_dt;
  for (auto c : {it, it == sorted_times.begin() ? it : it - 1}) {
    if (c == sorted_times.end()) continue;
    const double dt = std::abs(*c - t);
    if (dt <= best_dt) {
      best_dt = dt;
      best = c - sorted_times.begin();
    }
  }
  return best;
}

std::optional<Eigen::Isometry3d> poseAtTime(const std::vector<StampedPose>& sorted, double t_s,
                                            double max_dt_s, double max_gap_s,
                                            const std::string& source, std::string* problem) {
  auto time = [](const StampedPose& p) { return static_cast<double>(p.utime) * 1e-6; };
  auto it = std::lower_bound(sorted.begin(), sorted.end(), t_s,
                             [&](const StampedPose& e, double value) { return time(e) < value; });
  if (it != sorted.end() && it != sorted.begin()) {
    const double tb = time(*it), ta = time(*(it - 1));
    // The gap from the integer utimes: seconds near 1.7e9 differ from 0.2 in the 8th digit.
    const double gap_s = static_cast<double>(it->utime - (it - 1)->utime) * 1e-6;
    if (gap_s <= std::max(max_gap_s, 2.0 * max_dt_s) + 1e-9) {
      const double s = (tb > ta) ? (t_s - ta) / (tb - ta) : 0.0;
      return interpolatePose((it - 1)->T_W_C, it->T_W_C, s);
    }
  }
  std::vector<double> times;
  times.reserve(sorted.size());
  for (const StampedPose& p : sorted) times.push_back(time(p));
  const long best = nearestIndex(times, t_s, max_dt_s);
  if (best >= 0) return sorted[static_cast<size_t>(best)].T_W_C;
  std::ostringstream msg;
  msg.precision(6);
  msg << std::fixed << source << ": no pose within " << max_dt_s << " s of depth time " << t_s
      << ", nor two at most " << std::max(max_gap_s, 2.0 * max_dt_s)
      << " s apart around it (--max-pose-gap-ms)";
  *problem = msg.str();
  return std::nullopt;
}

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

std::vector<std::string> unpairedFiles(const std::vector<std::pair<long long, std::string>>& frames,
                                       const std::string& dir, const std::string& pattern) {
  std::set<long long> numbers;
  for (const auto& f : frames) numbers.insert(f.first);
  std::vector<std::string> out;
  for (const auto& f : listNumberedFiles(dir, pattern)) {
    if (!numbers.count(f.first)) out.push_back(f.second);
  }
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

namespace {

// The q-quantile of values (reordered).
double quantile(std::vector<uint16_t>* values, double q) {
  const size_t k = std::min(values->size() - 1, static_cast<size_t>(q * values->size()));
  std::nth_element(values->begin(), values->begin() + static_cast<long>(k), values->end());
  return static_cast<double>((*values)[k]);
}

}  // namespace

DepthValueSample sampleDepthValues(const std::vector<std::string>& paths, size_t max_images) {
  DepthValueSample sample;
  std::vector<uint16_t> values;
  // Images spread over the sequence: one image may face a near wall.
  const size_t images = std::min(max_images, paths.size());
  for (size_t k = 0; k < images; ++k) {
    const size_t index = images > 1 ? k * (paths.size() - 1) / (images - 1) : 0;
    DepthImage depth;
    try {
      depth = readDepthFile(paths[index]);
    } catch (const Error&) {
      continue;
    }
    std::vector<uint16_t> image_values;
    for (int v = 0; v < depth.height(); v += 2) {
      const uint16_t* row = depth.row(v);
      for (int u = 0; u < depth.width(); u += 2) {
        if (row[u] > 0) image_values.push_back(row[u]);
      }
    }
    if (image_values.empty()) continue;
    ++sample.images;
    sample.largest_p99 = std::max(sample.largest_p99, quantile(&image_values, 0.99));
    values.insert(values.end(), image_values.begin(), image_values.end());
  }
  if (!values.empty()) sample.median = quantile(&values, 0.5);
  return sample;
}

std::string formatDepthScale(double scale) {
  std::ostringstream out;
  if (std::abs(scale - 0.001) < 1e-12) {
    out << "0.001 m per unit (mm)";
  } else if (std::abs(scale - 1.0 / 5000.0) < 1e-12) {
    out << "1/5000 m per unit (TUM)";
  } else {
    out << scale << " m per unit";
  }
  return out.str();
}

void checkPrincipalPoint(const PinholeCamera& camera, const std::string& from) {
  const double w = camera.width, h = camera.height;
  if (camera.cx > 0.25 * w && camera.cx < 0.75 * w && camera.cy > 0.25 * h &&
      camera.cy < 0.75 * h) {
    return;
  }
  std::ostringstream msg;
  msg << from << ": principal point (" << camera.cx << ", " << camera.cy
      << ") lies outside the middle half of the " << camera.width << "x" << camera.height
      << " depth image";
  // Images resized after calibration keep a principal point at the old size's centre.
  const double kx = 2.0 * camera.cx / w, ky = 2.0 * camera.cy / h;
  if (kx > 0.2 && kx < 10.0 && std::abs(kx / ky - 1.0) < 0.05) {
    PinholeCamera original = camera;
    original.width = static_cast<int>(std::lround(w * kx));
    original.height = static_cast<int>(std::lround(h * ky));
    const PinholeCamera fitted = original.resized(camera.width, camera.height);
    msg.precision(6);
    msg << "; the intrinsics look like those of a " << original.width << "x" << original.height
        << " image: for these images pass --intrinsics " << fitted.fx << "," << fitted.fy << ","
        << fitted.cx << "," << fitted.cy;
  } else {
    msg << "; give the depth camera's intrinsics (--intrinsics fx,fy,cx,cy)";
  }
  throw Error(msg.str());
}

void readDepthPng(const std::string& path, int width, int height, DatasetFrame* frame) {
  frame->depth_png = readFileBytes(path);
  frame->rgbd.depth = decodeDepthPng(frame->depth_png.data(), frame->depth_png.size(), path);
  checkImageSize(path, "depth", frame->rgbd.depth.width(), frame->rgbd.depth.height(), width,
                 height);
}

void readRegisteredColor(const std::string& path, int width, int height, DatasetFrame* frame) {
  const std::vector<uint8_t> bytes = readFileBytes(path);
  frame->rgbd.color = decodeColor(bytes.data(), bytes.size(), path);
  checkImageSize(path, "colour", frame->rgbd.color.width(), frame->rgbd.color.height(), width,
                 height);
  if (isCompleteJpeg(bytes.data(), bytes.size())) frame->color_jpeg = bytes;
  frame->color_stem = fileStem(path);
  frame->color_source_width = width;
  frame->color_source_height = height;
}

}  // namespace internal
}  // namespace panmap
