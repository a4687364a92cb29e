// The generic RGB-D export: rgb/ (or color/) and depth/ image folders, an intrinsics file
// (3x3 or 4x4 matrix, or fx fy cx cy) and a trajectory file (TUM, a matrix per line, stacked
// 4x4) or a folder of per-frame 4x4 files. Images pair by frame number or name, by position,
// or by timestamp; depth units are mm unless the values say 1/5000 m (TUM) or the user says
// otherwise. What was detected is reported by notes(), so a wrong guess is visible.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/internal/readers.h"
#include "panmap/io/opencv_image.h"
#include "panmap/io/pose_list.h"
#include "panmap/io/text_files.h"
#include "panmap/io/timestamps.h"

namespace panmap {
namespace internal {
namespace {

constexpr const char* kColorFolders[] = {"rgb", "color", "colour", "image", "images"};
constexpr const char* kIntrinsicsFiles[] = {
    "intrinsic.txt", "intrinsics.txt", "camera-intrinsics.txt",         "camera_intrinsics.txt",
    "K.txt",         "cam_K.txt",      "intrinsic/intrinsic_depth.txt", "intrinsic_depth.txt"};
constexpr const char* kPoseFiles[] = {"gt_pose.txt",      "groundtruth.txt", "poses.txt",
                                      "pose.txt",         "trajectory.txt",  "traj.txt",
                                      "camera_poses.txt", "trajectory.log"};
constexpr const char* kPoseFolders[] = {"pose", "poses"};

// Depth values above these (median, 99th percentile) are implausible in millimetres for an
// indoor RGB-D sensor but typical of TUM's 1/5000 m.
constexpr double kMaxMedianDepthMm = 6500.0;
constexpr double kMaxP99DepthMm = 15000.0;
// A median beyond this in mm is possible (a hall) but is also TUM's 1/5000 m at 0.8-1.3 m.
constexpr double kFarMedianDepthMm = 4000.0;
// Depth images, spread over the sequence, whose values decide the depth unit.
constexpr size_t kDepthScaleImages = 9;

struct NamedFile {
  std::string name;
  std::string stem;
  bool numbered = false;
  double number = 0.0;  ///< the last number in the stem (a frame number or a timestamp)
};

bool hasExtension(const std::string& name, std::initializer_list<const char*> extensions) {
  std::string ext = std::filesystem::path(name).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  for (const char* e : extensions) {
    if (ext == e) return true;
  }
  return false;
}

// Files of a folder with one of the extensions, sorted by number when every name carries a
// distinct one (so 10.png follows 9.png), else by name.
std::vector<NamedFile> listFiles(const std::string& dir,
                                 std::initializer_list<const char*> extensions) {
  namespace fs = std::filesystem;
  static const std::regex number_re(R"((\d+(?:\.\d+)?))");
  std::vector<NamedFile> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (!entry.is_regular_file(ec)) continue;
    NamedFile f;
    f.name = entry.path().filename().string();
    if (!hasExtension(f.name, extensions)) continue;
    f.stem = entry.path().stem().string();
    for (std::sregex_iterator it(f.stem.begin(), f.stem.end(), number_re), end; it != end; ++it) {
      f.numbered = true;
      f.number = std::strtod((*it)[1].str().c_str(), nullptr);
    }
    files.push_back(std::move(f));
  }
  if (ec) throw Error("cannot list " + dir + ": " + ec.message());
  std::sort(files.begin(), files.end(),
            [](const NamedFile& a, const NamedFile& b) { return a.name < b.name; });
  bool by_number =
      std::all_of(files.begin(), files.end(), [](const NamedFile& f) { return f.numbered; });
  if (by_number) {
    std::vector<double> numbers;
    for (const NamedFile& f : files) numbers.push_back(f.number);
    std::sort(numbers.begin(), numbers.end());
    by_number = std::adjacent_find(numbers.begin(), numbers.end()) == numbers.end();
  }
  if (by_number) {
    std::sort(files.begin(), files.end(),
              [](const NamedFile& a, const NamedFile& b) { return a.number < b.number; });
  }
  return files;
}

bool allNumbered(const std::vector<NamedFile>& files) {
  return std::all_of(files.begin(), files.end(), [](const NamedFile& f) { return f.numbered; });
}

// Names that are timestamps (seconds with a fraction, or Unix times) rather than frame numbers.
bool areTimestamps(const std::vector<NamedFile>& files) {
  if (files.empty() || !allNumbered(files)) return false;
  return std::any_of(files.begin(), files.end(), [](const NamedFile& f) {
    return f.number != std::floor(f.number) || f.number > 1e8;
  });
}

// Timestamp names as seconds (names in ms, us or ns are scaled); the unit's name.
const char* namesInSeconds(std::vector<NamedFile>* files) {
  std::vector<double> numbers;
  for (const NamedFile& f : *files) numbers.push_back(f.number);
  const TimestampUnit unit = timestampUnitOf(numbers);
  for (NamedFile& f : *files) f.number *= unit.seconds_per_unit;
  return unit.name;
}

// The key two files of one frame share: the number when both folders number their files,
// else the stem.
std::string keyOf(const NamedFile& f, bool numbers) {
  if (!numbers) return f.stem;
  std::ostringstream key;
  key.precision(17);
  key << f.number;
  return key.str();
}

std::string firstExisting(const std::string& dir, const char* const* names, size_t count,
                          bool folders) {
  for (size_t i = 0; i < count; ++i) {
    const std::string path = dir + "/" + names[i];
    if (folders ? isDirectory(path) : isRegularFile(path)) return path;
  }
  return "";
}

template <size_t N>
std::string joined(const char* const (&names)[N]) {
  std::string out;
  for (size_t i = 0; i < N; ++i) out += std::string(i ? ", " : "") + names[i];
  return out;
}

class FolderReader : public DatasetReader {
 public:
  FolderReader(const std::string& dir, const DatasetOptions& options)
      : dir_(dir), options_(options) {
    const std::string missing = missingForFolder(dir);
    if (!missing.empty()) throw Error(dir + ": not an RGB-D folder (" + missing + ")");
    color_dir_ = firstExisting(dir, kColorFolders, std::size(kColorFolders), true);
    depth_dir_ = dir + "/depth";
    std::vector<NamedFile> colors = listFiles(color_dir_, {".png", ".jpg", ".jpeg"});
    std::vector<NamedFile> depths = listFiles(depth_dir_, {".png"});
    if (depths.empty()) throw Error(depth_dir_ + ": no PNG depth images");
    if (colors.empty()) throw Error(color_dir_ + ": no PNG or JPEG colour images");
    if (areTimestamps(depths)) time_unit_ = namesInSeconds(&depths);
    if (areTimestamps(colors)) namesInSeconds(&colors);
    pairImages(colors, depths);
    timestamps_ = areTimestamps(depths);
    readCamera();
    readPoses();
    detectDepthScale();
  }

  std::string layoutName() const override { return "folder"; }
  size_t size() const override { return frames_.size(); }
  size_t unmatchedFrames() const override { return unmatched_; }
  std::string unmatchedWhat() const override {
    return std::string("depth images without a colour image ") +
           (paired_in_time_ ? "in time" : "of the same name") + " (first: " + first_unmatched_ +
           ")";
  }
  std::vector<std::string> notes() const override { return notes_; }
  bool posesAreQuaternions() const override {
    return !pose_folder_ && list_.format == PoseList::Format::kTum;
  }

  DatasetFrame read(size_t index) const override {
    const Frame& f = frames_.at(index);
    DatasetFrame frame;
    const std::string depth_path = depth_dir_ + "/" + f.depth.name;
    readDepthPng(depth_path, camera_.width, camera_.height, &frame);
    const std::string color_path = color_dir_ + "/" + f.color.name;
    const std::vector<uint8_t> color_bytes = readFileBytes(color_path);
    ColorImage color = decodeColor(color_bytes.data(), color_bytes.size(), color_path);
    checkImageSize(color_path, "colour", color.width(), color.height(), color_width_,
                   color_height_);
    frame.color_stem = f.color.stem;
    frame.color_source_width = color.width();
    frame.color_source_height = color.height();
    if (color.width() == camera_.width && color.height() == camera_.height) {
      if (isCompleteJpeg(color_bytes.data(), color_bytes.size())) frame.color_jpeg = color_bytes;
      frame.rgbd.color = std::move(color);
    } else {
      // A colour camera of another resolution, taken as aligned with depth (common practice for
      // exports without extrinsics): resampled to the depth size.
      resizeColorMap(camera_.width, camera_.height, color.width(), color.height(),
                     &frame.color_map_u, &frame.color_map_v);
      cv::Mat registered;
      cv::remap(asMat(color), registered, asMat(frame.color_map_u), asMat(frame.color_map_v),
                cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0, 0, 0));
      frame.rgbd.color = colorFromMat(registered);
    }
    frame.rgbd.utime = timestamps_ ? utimeOfSeconds(f.depth.number, depth_path)
                       : !utime_by_frame_.empty()
                           ? utime_by_frame_.at(index)
                           : frameUtime(frameNumber(index), options_.frame_rate_hz);
    frame.rgbd.frame_id = frameNumber(index);
    frame.rgbd.camera_name = "folder";
    frame.rgbd.camera = camera_;
    frame.rgbd.depth_scale_m = depth_scale_m_;
    frame.T_W_C = poseOf(index, &frame.pose_problem);
    return frame;
  }

 private:
  struct Frame {
    NamedFile color;
    NamedFile depth;
  };

  long long frameNumber(size_t index) const {
    const NamedFile& d = frames_.at(index).depth;
    return integer_numbers_ ? static_cast<long long>(d.number) : static_cast<long long>(index);
  }

  void pairImages(const std::vector<NamedFile>& colors, const std::vector<NamedFile>& depths) {
    const bool numbers = allNumbered(colors) && allNumbered(depths);
    integer_numbers_ = numbers && !areTimestamps(depths);
    const std::string color_name = std::filesystem::path(color_dir_).filename().string() + "/";
    std::string how;
    FramePairing pairing = options_.pairing;
    if (pairing != FramePairing::kTime) {
      std::map<std::string, size_t> by_key;
      for (size_t i = 0; i < colors.size(); ++i) by_key.emplace(keyOf(colors[i], numbers), i);
      std::vector<Frame> named;
      for (const NamedFile& d : depths) {
        const auto it = by_key.find(keyOf(d, numbers));
        if (it != by_key.end()) named.push_back({colors[it->second], d});
      }
      const bool positional = colors.size() == depths.size();
      if (!named.empty() && (pairing == FramePairing::kName || 2 * named.size() >= depths.size())) {
        frames_ = std::move(named);
        how = !numbers                ? "by file name"
              : areTimestamps(depths) ? "by the timestamp in the name"
                                      : "by frame number";
      } else if (pairing == FramePairing::kAuto && areTimestamps(colors) && areTimestamps(depths)) {
        pairing = FramePairing::kTime;
      } else if (positional) {
        for (size_t i = 0; i < depths.size(); ++i) frames_.push_back({colors[i], depths[i]});
        how = "by position in sorted order (the names do not pair, the counts agree)";
      }
    }
    if (pairing == FramePairing::kTime) {
      if (!areTimestamps(colors) || !areTimestamps(depths)) {
        throw Error(dir_ + ": pairing by time needs timestamps as file names in " + color_name +
                    " and depth/");
      }
      std::vector<double> color_times;
      for (const NamedFile& c : colors) color_times.push_back(c.number);
      for (const NamedFile& d : depths) {
        const long c = nearestIndex(color_times, d.number, options_.tum_max_dt_s);
        if (c >= 0) frames_.push_back({colors[static_cast<size_t>(c)], d});
      }
      std::ostringstream text;
      text << "by timestamp (within " << options_.tum_max_dt_s << " s)";
      how = text.str();
    }
    if (frames_.empty()) {
      throw Error(dir_ + ": cannot pair " + std::to_string(colors.size()) + " images in " +
                  color_name + " with " + std::to_string(depths.size()) +
                  " in depth/ (names differ, counts differ, names are not timestamps)");
    }
    unmatched_ = depths.size() - frames_.size();
    paired_in_time_ = pairing == FramePairing::kTime;
    if (unmatched_ > 0) {
      std::set<std::string> paired;
      for (const Frame& f : frames_) paired.insert(f.depth.name);
      for (const NamedFile& d : depths) {
        if (!paired.count(d.name)) {
          first_unmatched_ = "depth/" + d.name;
          break;
        }
      }
    }
    // Paired by name, a colour image left over is a frame whose depth image is missing.
    const size_t colors_left = how.rfind("by f", 0) == 0 || how.rfind("by the", 0) == 0
                                   ? colors.size() - std::min(colors.size(), frames_.size())
                                   : 0;
    std::ostringstream note;
    note << "images: " << frames_.size() << " frames from " << color_name << " and depth/, paired "
         << how;
    if (unmatched_) note << "; " << unmatched_ << " depth images without a colour image";
    if (colors_left) note << "; " << colors_left << " colour images without a depth image";
    if (integer_numbers_ && (unmatched_ || colors_left)) note << numberShiftWarning(colors, depths);
    if (time_unit_ != std::string("seconds")) {
      note << "; the names are timestamps in " << time_unit_;
    }
    notes_.push_back(note.str());
  }

  void readCamera() {
    Eigen::Vector4d k;
    std::string from;
    if (options_.intrinsics) {
      k = *options_.intrinsics;
      from = options_.intrinsics_file.empty() ? "--intrinsics" : options_.intrinsics_file;
    } else {
      from = firstExisting(dir_, kIntrinsicsFiles, std::size(kIntrinsicsFiles), false);
      if (from.empty()) {
        throw Error(dir_ + ": no intrinsics file (looked for " + joined(kIntrinsicsFiles) +
                    "; pass --intrinsics FILE or fx,fy,cx,cy)");
      }
      k = readIntrinsicsFile(from);
    }
    camera_ = PinholeCamera{k(0), k(1), k(2), k(3), 0, 0};
    const std::string first_depth = depth_dir_ + "/" + frames_.front().depth.name;
    first_depth_ = readDepthFile(first_depth);
    camera_.width = first_depth_.width();
    camera_.height = first_depth_.height();
    std::string why;
    if (!camera_.isValid(&why)) throw Error(from + ": " + why);
    const ColorImage color = readColorFile(color_dir_ + "/" + frames_.front().color.name);
    color_width_ = color.width();
    color_height_ = color.height();
    std::ostringstream note;
    note << "intrinsics: " << from << " (fx " << k(0) << ", fy " << k(1) << ", cx " << k(2)
         << ", cy " << k(3) << "), depth " << camera_.width << "x" << camera_.height << ", colour "
         << color_width_ << "x" << color_height_;
    if (color_width_ != camera_.width || color_height_ != camera_.height) {
      note << " (resized to the depth size)";
      // Resizing another shape stretches colour and masks over the depth: fine for a camera
      // whose two images share a field of view, wrong for a 16:9 colour over 4:3 depth.
      const double stretch = (static_cast<double>(color_width_) / color_height_) /
                             (static_cast<double>(camera_.width) / camera_.height);
      if (std::abs(stretch - 1.0) > 0.01) {
        note << "; warning: colour and depth differ in shape (" << color_width_ << ":"
             << color_height_ << " against " << camera_.width << ":" << camera_.height
             << "), so colour and masks are stretched onto the depth, which is right only if "
                "both images see the same field of view";
      }
    }
    if (!hasCentredPrincipalPoint(camera_, camera_.width, camera_.height)) {
      // One intrinsics file for two image sizes is often the colour camera's: its principal
      // point lies near the colour image's centre, far from a smaller depth image's. Mapped with
      // it, every point would be shifted by half an image.
      const double aspect_color = static_cast<double>(color_width_) / color_height_;
      const double aspect_depth = static_cast<double>(camera_.width) / camera_.height;
      const bool fits_color = hasCentredPrincipalPoint(camera_, color_width_, color_height_) &&
                              std::abs(aspect_color / aspect_depth - 1.0) <= 0.02;
      if (!fits_color && options_.intrinsics) {
        // Given on the command line: a cropped sensor may really have it there.
        note << "; the principal point lies outside the middle half of the depth image: taken "
             << "as given";
      } else if (!fits_color) {
        std::ostringstream why;
        why << from << ": principal point (" << k(2) << ", " << k(3)
            << ") lies outside the middle half of the " << camera_.width << "x" << camera_.height
            << " depth image; give the depth camera's intrinsics (--intrinsics "
            << "fx,fy,cx,cy)";
        throw Error(why.str());
      } else {
        PinholeCamera color_camera = camera_;
        color_camera.width = color_width_;
        color_camera.height = color_height_;
        camera_ = color_camera.resized(camera_.width, camera_.height);
        note << "; the colour camera's (principal point at the colour image's centre), scaled to "
             << "the depth size: fx " << camera_.fx << ", fy " << camera_.fy << ", cx "
             << camera_.cx << ", cy " << camera_.cy;
      }
    }
    notes_.push_back(note.str());
  }

  // True when the principal point lies in the middle half of a width x height image, as it
  // does for every camera's own images.
  static bool hasCentredPrincipalPoint(const PinholeCamera& camera, int width, int height) {
    return camera.cx > 0.25 * width && camera.cx < 0.75 * width && camera.cy > 0.25 * height &&
           camera.cy < 0.75 * height;
  }

  void readPoses() {
    poses_from_ = options_.poses_path;
    if (poses_from_.empty()) {
      poses_from_ = firstExisting(dir_, kPoseFiles, std::size(kPoseFiles), false);
    }
    if (poses_from_.empty()) {
      poses_from_ = firstExisting(dir_, kPoseFolders, std::size(kPoseFolders), true);
    }
    if (poses_from_.empty()) {
      no_poses_ = dir_ + ": no pose file (looked for " + joined(kPoseFiles) + " and folders " +
                  joined(kPoseFolders) + "; pass --poses FILE)";
      notes_.push_back("poses: none found");
      return;
    }
    if (isDirectory(poses_from_)) {
      const std::vector<NamedFile> files = listFiles(poses_from_, {".txt"});
      const bool numbers = allNumbered(files) && allNumbered(depthFiles());
      for (const NamedFile& f : files) pose_files_.emplace(keyOf(f, numbers), f.name);
      pose_key_by_number_ = numbers;
      pose_folder_ = true;
      notes_.push_back("poses: a 4x4 file per frame in " + poses_from_ + " (" +
                       std::to_string(files.size()) + " files)");
      return;
    }
    if (!isRegularFile(poses_from_)) throw Error(poses_from_ + ": pose file missing");
    const PoseList list = readPoseList(poses_from_, options_.pose_tolerance);
    std::string how;
    if (list.format == PoseList::Format::kTum) {
      std::map<long long, size_t> by_number;
      const bool integer_times =
          std::all_of(list.times_s.begin(), list.times_s.end(),
                      [](double t) { return t == std::floor(t) && std::abs(t) < 1e15; });
      if (integer_times && integer_numbers_) {
        for (size_t i = 0; i < list.times_s.size(); ++i) {
          by_number.emplace(static_cast<long long>(list.times_s[i]), i);
        }
      }
      size_t found = 0;
      for (size_t i = 0; i < frames_.size(); ++i) found += by_number.count(frameNumber(i));
      if (timestamps_) {
        how = "by timestamp";
        for (size_t i = 0; i < list.poses.size(); ++i) {
          if (!list.poses[i]) continue;
          StampedPose p;
          p.utime = utimeOfSeconds(list.times_s[i], poses_from_);
          p.T_W_C = *list.poses[i];
          timed_.push_back(p);
        }
        std::stable_sort(
            timed_.begin(), timed_.end(),
            [](const StampedPose& a, const StampedPose& b) { return a.utime < b.utime; });
      } else if (found == frames_.size()) {
        how = "by frame number (the timestamp column)";
        for (size_t i = 0; i < frames_.size(); ++i)
          by_frame_.push_back(by_number.at(frameNumber(i)));
      } else if (list.poses.size() == frames_.size()) {
        how = "by order (one pose per frame)";
        for (size_t i = 0; i < frames_.size(); ++i) by_frame_.push_back(i);
        // The time column is the recording's clock: frames take it rather than --rate's, or a
        // trajectory written with these times matched a third of the frames at a 10 Hz
        // recording and its ATE judged a perfect map 41 cm off.
        const bool increasing =
            std::adjacent_find(list.times_s.begin(), list.times_s.end(),
                               [](double a, double b) { return b <= a; }) == list.times_s.end();
        if (increasing) {
          for (const double t : list.times_s) {
            utime_by_frame_.push_back(utimeOfSeconds(t, poses_from_));
          }
          how += ", frame times from its time column";
        }
      } else {
        throw Error(poses_from_ + ": " + std::to_string(list.poses.size()) + " TUM poses for " +
                    std::to_string(frames_.size()) +
                    " frames whose names are not timestamps, and the timestamp column does not "
                    "number the frames: cannot pair them" +
                    framesLeftOut());
      }
    } else if (list.poses.size() == frames_.size()) {
      how = "by order (one pose per frame)";
      for (size_t i = 0; i < frames_.size(); ++i) by_frame_.push_back(i);
    } else {
      throw Error(poses_from_ + ": " + std::to_string(list.poses.size()) + " poses (" +
                  poseListFormatName(list.format) + ") for " + std::to_string(frames_.size()) +
                  " frames: a pose per frame needed" + framesLeftOut());
    }
    list_ = list;
    notes_.push_back("poses: " + poses_from_ + " (" + poseListFormatName(list.format) +
                     "), matched " + how);
  }

  // For a pose count that does not match the frames: the frames pairing left out.
  std::string framesLeftOut() const {
    if (unmatched_ == 0) return "";
    return " (" + std::to_string(unmatched_) + " depth images were left out for want of a " +
           "colour image, first " + first_unmatched_ + ")";
  }

  // Integer-numbered colour and depth images whose numbers are the same run shifted (colour
  // 1..60, depth 0..59): paired by number, every colour image lands one frame off.
  static std::string numberShiftWarning(const std::vector<NamedFile>& colors,
                                        const std::vector<NamedFile>& depths) {
    if (colors.size() != depths.size() || colors.empty()) return "";
    std::vector<double> c, d;
    for (const NamedFile& f : colors) c.push_back(f.number);
    for (const NamedFile& f : depths) d.push_back(f.number);
    std::sort(c.begin(), c.end());
    std::sort(d.begin(), d.end());
    const double shift = c.front() - d.front();
    if (shift == 0.0) return "";
    for (size_t i = 0; i < c.size(); ++i) {
      if (c[i] - d[i] != shift) return "";
    }
    std::ostringstream out;
    out << "; WARNING: the colour images are numbered " << static_cast<long long>(c.front()) << "-"
        << static_cast<long long>(c.back()) << " and the depth images "
        << static_cast<long long>(d.front()) << "-" << static_cast<long long>(d.back())
        << ": if they are the same frames counted from another start, renumber one folder "
        << "(paired by number, each frame's colour comes from another frame)";
    return out.str();
  }

  std::vector<NamedFile> depthFiles() const {
    std::vector<NamedFile> out;
    for (const Frame& f : frames_) out.push_back(f.depth);
    return out;
  }

  std::optional<Eigen::Isometry3d> poseOf(size_t index, std::string* problem) const {
    if (!no_poses_.empty()) {
      *problem = no_poses_;
      return std::nullopt;
    }
    const Frame& f = frames_.at(index);
    if (pose_folder_) {
      const auto it = pose_files_.find(keyOf(f.depth, pose_key_by_number_));
      if (it == pose_files_.end()) {
        *problem = poses_from_ + ": no pose file for depth image " + f.depth.name;
        return std::nullopt;
      }
      return readPoseFile(poses_from_ + "/" + it->second, options_.pose_tolerance, problem);
    }
    if (timestamps_ && list_.format == PoseList::Format::kTum) {
      return poseAtTime(timed_, f.depth.number, options_.tum_max_dt_s, options_.max_pose_gap_s,
                        poses_from_, problem);
    }
    const size_t i = by_frame_.at(index);
    if (!list_.poses[i]) *problem = list_.problems[i];
    return list_.poses[i];
  }

  void detectDepthScale() {
    if (options_.depth_scale_m) {
      depth_scale_m_ = *options_.depth_scale_m;
      notes_.push_back("depth scale: " + formatDepthScale(depth_scale_m_) + " (given)");
      return;
    }
    std::vector<std::string> paths;
    for (const Frame& f : frames_) paths.push_back(depth_dir_ + "/" + f.depth.name);
    const DepthValueSample sample = sampleDepthValues(paths, kDepthScaleImages);
    const size_t images = sample.images;
    if (images == 0) {
      depth_scale_m_ = 0.001;
      notes_.push_back("depth scale: " + formatDepthScale(depth_scale_m_) + " (assumed: the " +
                       std::to_string(std::min(kDepthScaleImages, paths.size())) +
                       " depth images looked at are empty; --depth-scale overrides)");
      return;
    }
    const double median = sample.median, largest_p99 = sample.largest_p99;
    const bool mm = median <= kMaxMedianDepthMm && largest_p99 <= kMaxP99DepthMm;
    depth_scale_m_ = mm ? 0.001 : 1.0 / 5000.0;
    std::ostringstream note;
    note.precision(3);
    note << "depth scale: " << formatDepthScale(depth_scale_m_) << ", detected from " << images
         << (images == 1 ? " image" : " images") << " (median " << median * depth_scale_m_
         << " m, largest 99th percentile " << largest_p99 * depth_scale_m_
         << " m; --depth-scale overrides)";
    if (mm && median > kFarMedianDepthMm) {
      note << "; WARNING: a median this far is unusual indoors: if the images are in TUM's "
           << "1/5000 m, pass --depth-scale 0.0002";
    }
    notes_.push_back(note.str());
  }

  std::string dir_;
  DatasetOptions options_;
  std::string color_dir_;
  std::string depth_dir_;
  std::vector<Frame> frames_;
  size_t unmatched_ = 0;
  bool paired_in_time_ = false;
  std::string first_unmatched_;  ///< the first depth image left without colour
  bool timestamps_ = false;
  const char* time_unit_ = "seconds";  ///< of the depth images' timestamp names
  bool integer_numbers_ = false;
  PinholeCamera camera_;
  int color_width_ = 0;
  int color_height_ = 0;
  DepthImage first_depth_;
  double depth_scale_m_ = 0.001;
  // Poses: a folder of files, a list matched by frame, or a time-stamped list.
  std::string poses_from_;
  std::string no_poses_;
  std::map<std::string, std::string> pose_files_;
  bool pose_folder_ = false;
  // Frame times from a TUM file matched by order (its time column), else empty.
  std::vector<int64_t> utime_by_frame_;
  bool pose_key_by_number_ = false;
  PoseList list_;
  std::vector<size_t> by_frame_;
  std::vector<StampedPose> timed_;
  std::vector<std::string> notes_;
};

}  // namespace

std::string missingForFolder(const std::string& dir) {
  if (firstExisting(dir, kColorFolders, std::size(kColorFolders), true).empty()) {
    return std::string("no colour folder (") + joined(kColorFolders) + ")";
  }
  if (!isDirectory(dir + "/depth")) return "no depth/ folder";
  return "";
}

std::unique_ptr<DatasetReader> makeFolderReader(const std::string& dir,
                                                const DatasetOptions& options) {
  return std::make_unique<FolderReader>(dir, options);
}

}  // namespace internal
}  // namespace panmap
