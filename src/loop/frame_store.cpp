#include "panmap/loop/frame_store.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <zlib.h>

#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/plane_codec.h"

namespace panmap {

namespace {

constexpr char kIndexName[] = "index.txt";
// Version 2 keeps depth and labels as zstd planes (io/plane_codec.h); version 1 kept PNGs
// (decoding them was most of a repair's time). Stores of either version are read and grow
// in their own format.
constexpr char kVersionPrefix[] = "panmap-frame-store ";
constexpr int kVersion = 2;
// The zlib level version 1 stores were written with.
constexpr int kVersion1PngLevel = 6;
// Poses the mapper accepts (Mapper::validate uses the same tolerance) must be storable.
constexpr double kRigidTolerance = 1e-4;
// Tokens of an index line, its CRC included.
constexpr size_t kFrameTokens = 30;
constexpr size_t kPoseTokens = 15;
constexpr size_t kMaskTokens = 9;
constexpr size_t kGeometricTokens = 6;
// The geometric segments' plane (version 2 only).
constexpr char kGeometricSuffix[] = ".geometric.zst";

// File names of a frame's images, by store version: version 1 split labels above 2^24 into a
// second PNG, a plane holds every int32 in one file.
struct Suffixes {
  const char* depth;
  const char* labels;
  const char* labels_hi;
  const char* masks;
  const char* masks_hi;
};

const Suffixes& suffixesOf(int version) {
  static const Suffixes kPng{".depth.png", ".labels.png", ".labels-hi.png", ".masks.png",
                             ".masks-hi.png"};
  static const Suffixes kPlanes{".depth.zst", ".labels.zst", ".labels-hi.png", ".masks.zst",
                                ".masks-hi.png"};
  return version == 1 ? kPng : kPlanes;
}

uint32_t crcOf(const uint8_t* data, size_t size) {
  uLong crc = crc32(0L, Z_NULL, 0);
  // zlib takes uInt lengths: feed large buffers in pieces.
  while (size > 0) {
    const uInt n = static_cast<uInt>(std::min<size_t>(size, 1u << 30));
    crc = crc32(crc, data, n);
    data += n;
    size -= n;
  }
  return static_cast<uint32_t>(crc);
}

uint32_t crcOf(const std::string& text) {
  return crcOf(reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

std::string hex32(uint32_t value) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "%08" PRIx32, value);
  return buf;
}

// 17 significant digits: every double reads back to the same bits (IEEE 754 round trip).
void appendDouble(std::string* line, double value) {
  char buf[40];
  std::snprintf(buf, sizeof(buf), " %.17g", value);
  *line += buf;
}

void appendPose(std::string* line, const Eigen::Isometry3d& T) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) appendDouble(line, T.matrix()(r, c));
  }
}

// Appends the line's CRC-32 (over everything before it) as its last token.
std::string sealed(std::string line) {
  const uint32_t crc = crcOf(line);
  return line + " " + hex32(crc);
}

bool parseInt64(const std::string& token, int64_t* out) {
  if (token.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(token.c_str(), &end, 10);
  if (errno != 0 || *end != '\0') return false;
  *out = v;
  return true;
}

bool parseUint(const std::string& token, int base, uint64_t* out) {
  if (token.empty() || token[0] == '-' || token[0] == '+') return false;
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(token.c_str(), &end, base);
  if (errno != 0 || *end != '\0') return false;
  *out = v;
  return true;
}

bool parseDouble(const std::string& token, double* out) {
  if (token.empty()) return false;
  char* end = nullptr;
  const double v = std::strtod(token.c_str(), &end);
  if (*end != '\0' || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

bool parsePose(const std::vector<std::string>& tokens, size_t first, Eigen::Isometry3d* T) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (!parseDouble(tokens[first + static_cast<size_t>(4 * r + c)], &m(r, c))) return false;
    }
  }
  if (!isRigidTransform(m, kRigidTolerance)) return false;
  T->matrix() = m;
  return true;
}

std::vector<std::string> splitSpaces(const std::string& line) {
  std::vector<std::string> tokens;
  std::istringstream in(line);
  std::string token;
  while (in >> token) tokens.push_back(token);
  return tokens;
}

// The line without its last token when that token is the CRC-32 of the rest; false otherwise.
bool checkSeal(const std::string& line, std::string* body) {
  const size_t space = line.rfind(' ');
  if (space == std::string::npos) return false;
  uint64_t crc = 0;
  const std::string token = line.substr(space + 1);
  if (token.size() != 8 || !parseUint(token, 16, &crc)) return false;
  *body = line.substr(0, space);
  return crcOf(*body) == crc;
}

std::string systemError(const std::string& what) { return what + ": " + std::strerror(errno); }

// Writes a whole file through AtomicFileWriter: a crash leaves the old file or the new one.
void writeAtomically(const std::string& path, const std::vector<uint8_t>& bytes) {
  AtomicFileWriter writer(path);
  writer.append(bytes.data(), bytes.size());
  writer.commit();
}

// CRC-32 of a file, read in pieces (the check on reopening must not hold whole frames).
bool fileCrc(const std::string& path, uint32_t* crc) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  uLong value = crc32(0L, Z_NULL, 0);
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const std::streamsize n = in.gcount();
    if (n > 0) {
      value = crc32(value, reinterpret_cast<const Bytef*>(buffer.data()), static_cast<uInt>(n));
    }
  }
  if (in.bad()) return false;
  *crc = static_cast<uint32_t>(value);
  return true;
}

}  // namespace

void FrameStoreConfig::check() const {
  if (color_quality < 1 || color_quality > 100) {
    throw Error("frame_store color_quality must be in [1, 100] (is " +
                std::to_string(color_quality) + ")");
  }
  if (compression_level < 1 || compression_level > 19) {
    throw Error("frame_store compression_level must be in [1, 19] (is " +
                std::to_string(compression_level) + ")");
  }
  if (folder.find('\n') != std::string::npos) {
    throw Error("frame_store folder must not contain a line break");
  }
}

FrameStore::FrameStore(const FrameStoreConfig& config)
    : FrameStore(config, true, Check::kContents) {}

FrameStore::FrameStore(const FrameStoreConfig& config, bool create, Check check) : config_(config) {
  config_.check();
  if (config_.folder.empty()) throw Error("frame_store folder is empty (the store is off)");
  index_path_ = config_.folder + "/" + kIndexName;
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(index_path_, ec)) {
    if (!create) throw Error("frame store " + config_.folder + ": no " + kIndexName + " there");
    fs::create_directories(config_.folder + "/frames", ec);
    if (ec) {
      throw Error("frame store: cannot create " + config_.folder + "/frames: " + ec.message());
    }
    // The version line goes in atomically: an index either exists whole or not at all.
    version_ = kVersion;
    const std::string header = kVersionPrefix + std::to_string(kVersion) + "\n";
    writeAtomically(index_path_, std::vector<uint8_t>(header.begin(), header.end()));
  } else {
    fs::create_directories(config_.folder + "/frames", ec);
    readIndex(check);
  }
  index_fd_ = ::open(index_path_.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (index_fd_ < 0) throw Error(systemError("frame store: cannot open " + index_path_));
  struct stat st {};
  if (::fstat(index_fd_, &st) != 0) {
    ::close(index_fd_);
    throw Error(systemError("frame store: cannot stat " + index_path_));
  }
  index_bytes_ = static_cast<uint64_t>(st.st_size);
}

FrameStore::~FrameStore() {
  if (index_fd_ >= 0) ::close(index_fd_);
}

std::unique_ptr<FrameStore> FrameStore::open(const std::string& folder, Check check,
                                             const FrameStoreConfig& config_template) {
  FrameStoreConfig config = config_template;
  config.folder = folder;
  return std::unique_ptr<FrameStore>(new FrameStore(config, false, check));
}

std::string FrameStore::framePath(int64_t utime, const char* suffix) const {
  return config_.folder + "/frames/" + std::to_string(utime) + suffix;
}

void FrameStore::readIndex(Check check) {
  const std::vector<uint8_t> bytes = readFileBytes(index_path_);
  const std::string text(bytes.begin(), bytes.end());
  const size_t first_end = text.find('\n');
  const std::string first = text.substr(0, std::min(first_end, text.size()));
  if (first_end == std::string::npos || (first != kVersionPrefix + std::string("1") &&
                                         first != kVersionPrefix + std::to_string(kVersion))) {
    throw Error("frame store " + config_.folder + ": " + kIndexName + " does not start with '" +
                kVersionPrefix + "1' or '" + kVersionPrefix + std::to_string(kVersion) + "'");
  }
  version_ = first.back() - '0';
  // A line without its line break was being appended when the process died: the frame's files
  // may be whole, but its line is not, so it is dropped (and cut off, so that the next line
  // appended starts on a line of its own).
  const size_t last_end = text.rfind('\n');
  if (last_end + 1 < text.size()) {
    problems_.push_back(std::string(kIndexName) + ": cut last line (" +
                        std::to_string(text.size() - last_end - 1) +
                        " bytes, a crash while appending) removed");
    if (::truncate(index_path_.c_str(), static_cast<off_t>(last_end + 1)) != 0) {
      throw Error(systemError("frame store: cannot cut " + index_path_));
    }
  }
  std::map<int64_t, int> frame_line;  // the line each entry comes from, for messages
  size_t pos = first_end + 1;
  int line_number = 1;
  while (pos <= last_end && pos < text.size()) {
    const size_t end = text.find('\n', pos);
    const std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    const std::string where = std::string(kIndexName) + " line " + std::to_string(line_number);
    std::string body;
    if (!checkSeal(line, &body)) {
      problems_.push_back(where + ": corrupt (checksum), ignored");
      continue;
    }
    const std::vector<std::string> tokens = splitSpaces(body);
    int64_t utime = 0;
    if (tokens.size() + 1 == kFrameTokens && tokens[0] == "frame" &&
        parseInt64(tokens[1], &utime)) {
      Entry e;
      PinholeCamera& c = e.camera;
      uint64_t width = 0, height = 0;
      bool ok = parseDouble(tokens[2], &c.fx) && parseDouble(tokens[3], &c.fy) &&
                parseDouble(tokens[4], &c.cx) && parseDouble(tokens[5], &c.cy) &&
                parseUint(tokens[6], 10, &width) && parseUint(tokens[7], 10, &height) &&
                width < (1u << 20) && height < (1u << 20) &&
                parseDouble(tokens[8], &e.depth_scale_m) && e.depth_scale_m > 0.0 &&
                parsePose(tokens, 9, &e.T_W_C);
      c.width = static_cast<int>(width);
      c.height = static_cast<int>(height);
      FileRecord* files[4] = {&e.depth, &e.labels, &e.labels_hi, &e.color};
      for (int f = 0; f < 4 && ok; ++f) {
        uint64_t crc = 0;
        ok = parseUint(tokens[21 + 2 * f], 10, &files[f]->size) &&
             parseUint(tokens[22 + 2 * f], 16, &crc) && crc <= 0xffffffffu;
        files[f]->crc = static_cast<uint32_t>(crc);
      }
      ok = ok && c.isValid() && e.depth.size > 0 && e.labels.size > 0;
      if (!ok) {
        problems_.push_back(where + ": not a valid frame line, ignored");
        continue;
      }
      // A frame added again after it was left out (its files lost) replaces the older line.
      entries_[utime] = e;  // its masks line, if any, follows
      frame_line[utime] = line_number;
    } else if (tokens.size() + 1 == kMaskTokens && tokens[0] == "masks" &&
               parseInt64(tokens[1], &utime)) {
      const auto it = entries_.find(utime);
      if (it == entries_.end()) {
        problems_.push_back(where + ": masks of utime " + std::to_string(utime) +
                            ", which no earlier line adds, ignored");
        continue;
      }
      Entry& e = it->second;
      FileRecord records[3];
      bool ok = true;
      for (int f = 0; f < 3 && ok; ++f) {
        uint64_t crc = 0;
        ok = parseUint(tokens[2 + 2 * f], 10, &records[f].size) &&
             parseUint(tokens[3 + 2 * f], 16, &crc) && crc <= 0xffffffffu;
        records[f].crc = static_cast<uint32_t>(crc);
      }
      if (!ok || records[0].size == 0 || records[2].size == 0) {
        problems_.push_back(where + ": not a valid masks line, ignored");
        continue;
      }
      e.masks = records[0];
      e.masks_hi = records[1];
      e.segments = records[2];
    } else if (tokens.size() + 1 == kGeometricTokens && tokens[0] == "geometric" &&
               parseInt64(tokens[1], &utime)) {
      const auto it = entries_.find(utime);
      uint64_t key = 0, crc = 0;
      FileRecord record;
      if (it == entries_.end() || it->second.masks.size == 0) {
        problems_.push_back(where + ": geometric segments of utime " + std::to_string(utime) +
                            ", which no earlier line adds with masks, ignored");
        continue;
      }
      if (version_ == 1 || !parseUint(tokens[2], 16, &key) ||
          !parseUint(tokens[3], 10, &record.size) || record.size == 0 ||
          !parseUint(tokens[4], 16, &crc) || crc > 0xffffffffu) {
        problems_.push_back(where + ": not a valid geometric line, ignored");
        continue;
      }
      record.crc = static_cast<uint32_t>(crc);
      it->second.geometric = record;
      it->second.geometric_key = key;
    } else if (tokens.size() + 1 == kPoseTokens && tokens[0] == "pose" &&
               parseInt64(tokens[1], &utime)) {
      Eigen::Isometry3d T;
      if (!parsePose(tokens, 2, &T)) {
        problems_.push_back(where + ": pose of utime " + std::to_string(utime) +
                            " is not a rigid transform, ignored");
        continue;
      }
      const auto it = entries_.find(utime);
      if (it == entries_.end()) {
        problems_.push_back(where + ": pose update of utime " + std::to_string(utime) +
                            ", which no earlier line adds, ignored");
        continue;
      }
      it->second.T_W_C = T;
    } else if (tokens.size() == 2 && tokens[0] == "correction" && parseInt64(tokens[1], &utime)) {
      // (utime holds the correction id here.)
      last_correction_id_ = std::max(last_correction_id_.value_or(utime), utime);
    } else {
      problems_.push_back(where + ": not a frame or pose line, ignored");
    }
  }
  for (auto it = entries_.begin(); it != entries_.end();) {
    const std::string problem = checkFiles(it->first, it->second, check);
    if (problem.empty()) {
      frame_bytes_ += it->second.bytes();
      ++it;
    } else {
      problems_.push_back(problem + " (" + kIndexName + " line " +
                          std::to_string(frame_line[it->first]) + "), frame left out");
      ++skipped_;
      it = entries_.erase(it);
    }
  }
}

std::string FrameStore::checkFiles(int64_t utime, const Entry& entry, Check check) const {
  const Suffixes& sfx = suffixesOf(version_);
  const std::pair<const FileRecord*, const char*> files[8] = {
      {&entry.depth, sfx.depth},          {&entry.labels, sfx.labels},
      {&entry.labels_hi, sfx.labels_hi},  {&entry.color, ".color.jpg"},
      {&entry.masks, sfx.masks},          {&entry.masks_hi, sfx.masks_hi},
      {&entry.segments, ".segments.txt"}, {&entry.geometric, kGeometricSuffix}};
  const std::string what = "frame " + std::to_string(utime) + ": ";
  for (const auto& [record, suffix] : files) {
    if (record->size == 0) continue;
    const std::string path = framePath(utime, suffix);
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return what + path + " is missing";
    if (static_cast<uint64_t>(st.st_size) != record->size) {
      return what + path + " has " + std::to_string(st.st_size) + " bytes, the index says " +
             std::to_string(record->size) + " (cut or replaced)";
    }
    if (check == Check::kContents) {
      uint32_t crc = 0;
      if (!fileCrc(path, &crc)) return what + path + " cannot be read";
      if (crc != record->crc) return what + path + " is corrupt (CRC-32 differs from the index)";
    }
  }
  return {};
}

void FrameStore::appendIndexLine(const std::string& line) {
  const std::string text = line + "\n";
  const char* data = text.data();
  size_t left = text.size();
  while (left > 0) {
    const ssize_t n = ::write(index_fd_, data, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string message = systemError("frame store: cannot append to " + index_path_);
      // Cut what went in, so the next line does not continue a partial one.
      if (::ftruncate(index_fd_, static_cast<off_t>(index_bytes_)) != 0) {
        // The reopen check names a cut line; nothing more to do here.
      }
      throw Error(message);
    }
    data += n;
    left -= static_cast<size_t>(n);
  }
  // The line is in the file now (a failed sync below does not take it out): a later failure
  // must cut back to after it.
  index_bytes_ += text.size();
  // The line is the frame's commit point: durable before add() or updatePose() returns.
  if (::fsync(index_fd_) != 0) throw Error(systemError("frame store: cannot sync " + index_path_));
}

void FrameStore::add(int64_t utime, const Eigen::Isometry3d& T_W_C, const PinholeCamera& camera,
                     double depth_scale_m, const DepthImage& depth, const LabelImage& labels,
                     const ColorImage* color, const PanopticFrame* panoptic,
                     const GeometricSegments* geometric) {
  const std::string what = "frame store: frame " + std::to_string(utime);
  std::string why;
  if (!camera.isValid(&why)) throw Error(what + ": intrinsics: " + why);
  if (!isRigidTransform(T_W_C.matrix(), kRigidTolerance, &why)) {
    throw Error(what + ": pose: " + why);
  }
  if (!(depth_scale_m > 0.0 && std::isfinite(depth_scale_m))) {
    throw Error(what + ": depth_scale_m must be > 0");
  }
  const auto sizeMatches = [&](int w, int h) { return w == camera.width && h == camera.height; };
  const std::string camera_size =
      std::to_string(camera.width) + "x" + std::to_string(camera.height);
  if (!sizeMatches(depth.width(), depth.height())) {
    throw Error(what + ": depth image is not " + camera_size + " as the intrinsics say");
  }
  if (!sizeMatches(labels.width(), labels.height())) {
    throw Error(what + ": label image is not " + camera_size + " as the intrinsics say");
  }
  const bool with_color = config_.store_color && color && !color->empty();
  if (with_color && !sizeMatches(color->width(), color->height())) {
    throw Error(what + ": colour image is not " + camera_size + " as the intrinsics say");
  }
  if (panoptic && !sizeMatches(panoptic->segment_ids.width(), panoptic->segment_ids.height())) {
    throw Error(what + ": panoptic segment image is not " + camera_size + " as the intrinsics say");
  }
  // Kept only where a repair maps the frame again, and only as a plane.
  const bool with_geometric = panoptic && geometric && !geometric->ids.empty() && version_ != 1;
  if (with_geometric && !sizeMatches(geometric->ids.width(), geometric->ids.height())) {
    throw Error(what + ": geometric segment image is not " + camera_size +
                " as the intrinsics say");
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (entries_.count(utime) || pending_.count(utime)) {
      throw Error(what + " is already stored (a new pose goes through updatePose)");
    }
    pending_.insert(utime);
  }
  // Whatever happens below, the utime is no longer being added afterwards.
  struct PendingRelease {
    FrameStore* store;
    int64_t utime;
    ~PendingRelease() {
      std::lock_guard<std::mutex> lock(store->mutex_);
      store->pending_.erase(utime);
    }
  } release{this, utime};

  // Encoding and the file writes run outside the lock: they are the cost of add().
  Entry entry;
  entry.T_W_C = T_W_C;
  entry.camera = camera;
  entry.depth_scale_m = depth_scale_m;
  const auto store = [&](const std::vector<uint8_t>& bytes, const char* suffix, FileRecord* rec) {
    writeAtomically(framePath(utime, suffix), bytes);
    rec->size = bytes.size();
    rec->crc = crcOf(bytes.data(), bytes.size());
  };
  const Suffixes& sfx = suffixesOf(version_);
  if (version_ == 1) {
    store(encodeDepthPng(depth, kVersion1PngLevel), sfx.depth, &entry.depth);
  } else {
    store(encodePlane(depth, config_.compression_level), sfx.depth, &entry.depth);
  }
  // A plane holds every int32. A label PNG (version 1) holds 24 bits per pixel (COCO panoptic
  // RGB); super-point and segment ids stay far below 2^24 in practice, but an int32 has 8 more
  // bits: they go to a second PNG written only when some id uses them, so every int32
  // (negative ones too) round-trips. Returns whether the second file was written.
  const auto storePlanes = [&](const LabelImage& ids, const char* suffix, const char* hi_suffix,
                               FileRecord* rec, FileRecord* hi_rec) {
    if (version_ != 1) {
      store(encodePlane(ids, config_.compression_level), suffix, rec);
      return false;
    }
    LabelImage low(ids.width(), ids.height());
    LabelImage high(ids.width(), ids.height());
    bool any_high = false;
    for (size_t i = 0; i < ids.size(); ++i) {
      const uint32_t bits = static_cast<uint32_t>(ids.data()[i]);
      low.data()[i] = static_cast<int32_t>(bits & 0xffffffu);
      high.data()[i] = static_cast<int32_t>(bits >> 24);
      any_high = any_high || (bits >> 24) != 0;
    }
    store(encodeLabelPng(low, kVersion1PngLevel), suffix, rec);
    if (any_high) store(encodeLabelPng(high, kVersion1PngLevel), hi_suffix, hi_rec);
    return any_high;
  };
  const bool labels_high =
      storePlanes(labels, sfx.labels, sfx.labels_hi, &entry.labels, &entry.labels_hi);
  if (with_color) store(encodeJpeg(*color, config_.color_quality), ".color.jpg", &entry.color);
  bool masks_high = false;
  if (panoptic) {
    masks_high =
        storePlanes(panoptic->segment_ids, sfx.masks, sfx.masks_hi, &entry.masks, &entry.masks_hi);
    std::string text;
    char row[128];
    for (const PanopticSegment& seg : panoptic->segments) {
      // %.9g: every float reads back to the same bits.
      std::snprintf(row, sizeof(row), "%d %d %d %d %.9g\n", seg.id, seg.category,
                    seg.source_category, seg.is_thing ? 1 : 0, static_cast<double>(seg.score));
      text += row;
    }
    if (text.empty()) text = "\n";  // a segmentation without segments is still one
    store(std::vector<uint8_t>(text.begin(), text.end()), ".segments.txt", &entry.segments);
  }
  if (with_geometric) {
    store(encodePlane(geometric->ids, config_.compression_level), kGeometricSuffix,
          &entry.geometric);
    entry.geometric_key = geometric->config_key;
  }
  // Files an earlier, interrupted add() of this utime may have left (never in the index).
  if (!labels_high) std::remove(framePath(utime, sfx.labels_hi).c_str());
  if (!with_color) std::remove(framePath(utime, ".color.jpg").c_str());
  if (!masks_high) std::remove(framePath(utime, sfx.masks_hi).c_str());
  if (!panoptic) {
    std::remove(framePath(utime, sfx.masks).c_str());
    std::remove(framePath(utime, ".segments.txt").c_str());
  }
  if (!with_geometric) std::remove(framePath(utime, kGeometricSuffix).c_str());

  std::string line = "frame " + std::to_string(utime);
  for (double v : {camera.fx, camera.fy, camera.cx, camera.cy}) appendDouble(&line, v);
  line += " " + std::to_string(camera.width) + " " + std::to_string(camera.height);
  appendDouble(&line, depth_scale_m);
  appendPose(&line, T_W_C);
  for (const FileRecord* rec : {&entry.depth, &entry.labels, &entry.labels_hi, &entry.color}) {
    line += " " + std::to_string(rec->size) + " " + hex32(rec->crc);
  }
  std::string lines = sealed(line);
  if (panoptic) {
    // Appended in the same write as the frame line: a crash cuts at most the last line, and
    // a frame whose masks line was cut is re-integrated, not associated again.
    std::string masks = "masks " + std::to_string(utime);
    for (const FileRecord* rec : {&entry.masks, &entry.masks_hi, &entry.segments}) {
      masks += " " + std::to_string(rec->size) + " " + hex32(rec->crc);
    }
    lines += "\n" + sealed(masks);
  }
  if (with_geometric) {
    // After the masks line: cut away by a crash, the frame is segmented again when remapped.
    char key[24];
    std::snprintf(key, sizeof(key), "%016llx",
                  static_cast<unsigned long long>(entry.geometric_key));
    lines += "\n" + sealed("geometric " + std::to_string(utime) + " " + key + " " +
                           std::to_string(entry.geometric.size) + " " + hex32(entry.geometric.crc));
  }
  std::lock_guard<std::mutex> lock(mutex_);
  appendIndexLine(lines);
  entries_[utime] = entry;
  frame_bytes_ += entry.bytes();
}

void FrameStore::add(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                     const LabelImage& labels, const PanopticFrame* panoptic,
                     const GeometricSegments* geometric) {
  add(frame.utime, T_W_C, frame.camera, frame.depth_scale_m, frame.depth, labels,
      frame.color.empty() ? nullptr : &frame.color, panoptic, geometric);
}

void FrameStore::updatePose(int64_t utime, const Eigen::Isometry3d& T_W_C) {
  const std::string what = "frame store: frame " + std::to_string(utime);
  std::string why;
  if (!isRigidTransform(T_W_C.matrix(), kRigidTolerance, &why)) {
    throw Error(what + ": pose: " + why);
  }
  std::string line = "pose " + std::to_string(utime);
  appendPose(&line, T_W_C);
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = entries_.find(utime);
  if (it == entries_.end()) throw Error(what + " is not stored");
  appendIndexLine(sealed(line));
  it->second.T_W_C = T_W_C;
}

void FrameStore::recordCorrection(int64_t correction_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  appendIndexLine(sealed("correction " + std::to_string(correction_id)));
  last_correction_id_ = std::max(last_correction_id_.value_or(correction_id), correction_id);
}

std::optional<int64_t> FrameStore::lastCorrectionId() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_correction_id_;
}

StoredFrame FrameStore::load(int64_t utime, Parts parts) const {
  Entry entry;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = entries_.find(utime);
    if (it == entries_.end()) {
      throw Error("frame store " + config_.folder + ": no frame at utime " + std::to_string(utime));
    }
    entry = it->second;
  }
  // Checked against the index before decoding: a file that decodes can still be another
  // frame's.
  const auto read = [&](const char* suffix, const FileRecord& rec) {
    const std::string path = framePath(utime, suffix);
    std::vector<uint8_t> bytes = readFileBytes(path);
    if (bytes.size() != rec.size || crcOf(bytes.data(), bytes.size()) != rec.crc) {
      throw Error("frame store: frame " + std::to_string(utime) + ": " + path +
                  " differs from the index (" + std::to_string(bytes.size()) + " bytes, " +
                  std::to_string(rec.size) + " indexed, or a different CRC-32)");
    }
    return bytes;
  };
  StoredFrame out;
  out.T_W_C = entry.T_W_C;
  out.rgbd.utime = utime;
  out.rgbd.camera = entry.camera;
  out.rgbd.depth_scale_m = entry.depth_scale_m;
  const std::string name = "frame store: frame " + std::to_string(utime) + ": ";
  const Suffixes& sfx = suffixesOf(version_);
  {
    const std::vector<uint8_t> bytes = read(sfx.depth, entry.depth);
    out.rgbd.depth = version_ == 1 ? decodeDepthPng(bytes.data(), bytes.size(), name + "depth")
                                   : decodeDepthPlane(bytes.data(), bytes.size(), name + "depth");
  }
  const auto readPlanes = [&](const char* suffix, const FileRecord& rec, const char* hi_suffix,
                              const FileRecord& hi_rec, const std::string& what) {
    const std::vector<uint8_t> bytes = read(suffix, rec);
    if (version_ != 1) {
      if (hi_rec.size > 0) throw Error(name + what + ": a second plane in a version 2 store");
      return decodeLabelPlane(bytes.data(), bytes.size(), name + what);
    }
    LabelImage ids = decodeLabelPng(bytes.data(), bytes.size(), name + what);
    if (hi_rec.size > 0) {
      const std::vector<uint8_t> hi_bytes = read(hi_suffix, hi_rec);
      const LabelImage high = decodeLabelPng(hi_bytes.data(), hi_bytes.size(), name + what + "-hi");
      if (high.width() != ids.width() || high.height() != ids.height()) {
        throw Error(name + "the two " + what + " planes differ in size");
      }
      for (size_t i = 0; i < high.size(); ++i) {
        const uint32_t bits =
            static_cast<uint32_t>(ids.data()[i]) | (static_cast<uint32_t>(high.data()[i]) << 24);
        ids.data()[i] = static_cast<int32_t>(bits);
      }
    }
    return ids;
  };
  out.labels = readPlanes(sfx.labels, entry.labels, sfx.labels_hi, entry.labels_hi, "labels");
  const bool segmentation = parts == Parts::kAll;
  if (segmentation && entry.masks.size > 0) {
    out.has_panoptic = true;
    out.panoptic.utime = utime;
    out.panoptic.segment_ids =
        readPlanes(sfx.masks, entry.masks, sfx.masks_hi, entry.masks_hi, "masks");
    const std::vector<uint8_t> bytes = read(".segments.txt", entry.segments);
    std::istringstream in(std::string(bytes.begin(), bytes.end()));
    std::string row;
    while (std::getline(in, row)) {
      if (row.empty()) continue;
      const std::vector<std::string> t = splitSpaces(row);
      PanopticSegment seg;
      int64_t id = 0, category = 0, source = 0, thing = 0;
      double score = 0.0;
      if (t.size() != 5 || !parseInt64(t[0], &id) || !parseInt64(t[1], &category) ||
          !parseInt64(t[2], &source) || !parseInt64(t[3], &thing) || thing < 0 || thing > 1 ||
          !parseDouble(t[4], &score) || id != static_cast<int32_t>(id) ||
          category != static_cast<int32_t>(category) || source != static_cast<int32_t>(source)) {
        throw Error(name + "segments: not a segment line: '" + row.substr(0, 80) + "'");
      }
      seg.id = static_cast<int32_t>(id);
      seg.category = static_cast<int32_t>(category);
      seg.source_category = static_cast<int32_t>(source);
      seg.is_thing = thing == 1;
      seg.score = static_cast<float>(score);
      out.panoptic.segments.push_back(seg);
    }
  }
  if (segmentation && entry.geometric.size > 0) {
    const std::vector<uint8_t> bytes = read(kGeometricSuffix, entry.geometric);
    out.geometric.ids = decodeLabelPlane(bytes.data(), bytes.size(), name + "geometric segments");
    out.geometric.config_key = entry.geometric_key;
  }
  if (entry.color.size > 0) {
    const std::vector<uint8_t> bytes = read(".color.jpg", entry.color);
    out.rgbd.color = decodeColor(bytes.data(), bytes.size(), name + "colour");
  }
  const int w = entry.camera.width, h = entry.camera.height;
  const auto sized = [&](int iw, int ih) { return iw == w && ih == h; };
  if (!sized(out.rgbd.depth.width(), out.rgbd.depth.height()) ||
      !sized(out.labels.width(), out.labels.height()) ||
      (!out.rgbd.color.empty() && !sized(out.rgbd.color.width(), out.rgbd.color.height())) ||
      (out.has_panoptic &&
       !sized(out.panoptic.segment_ids.width(), out.panoptic.segment_ids.height())) ||
      (!out.geometric.ids.empty() &&
       !sized(out.geometric.ids.width(), out.geometric.ids.height()))) {
    throw Error(name + "an image's size differs from the stored intrinsics");
  }
  return out;
}

size_t FrameStore::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

bool FrameStore::has(int64_t utime) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.count(utime) > 0;
}

size_t FrameStore::sizeWithPanoptic() const {
  std::lock_guard<std::mutex> lock(mutex_);
  size_t n = 0;
  for (const auto& [utime, entry] : entries_) n += entry.masks.size > 0;
  return n;
}

std::vector<int64_t> FrameStore::utimes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<int64_t> out;
  out.reserve(entries_.size());
  for (const auto& [utime, entry] : entries_) out.push_back(utime);
  return out;
}

std::vector<StampedPose> FrameStore::trajectory() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<StampedPose> out;
  out.reserve(entries_.size());
  for (const auto& [utime, entry] : entries_) {
    StampedPose p;
    p.utime = utime;
    p.T_W_C = entry.T_W_C;
    out.push_back(p);
  }
  return out;
}

uint64_t FrameStore::bytesOnDisk() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frame_bytes_ + index_bytes_;
}

std::vector<std::string> FrameStore::problems() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return problems_;
}

size_t FrameStore::skipped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return skipped_;
}

FrameStore::FrameBytes FrameStore::frameBytes(int64_t utime) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = entries_.find(utime);
  if (it == entries_.end()) {
    throw Error("frame store " + config_.folder + ": no frame at utime " + std::to_string(utime));
  }
  FrameBytes out;
  out.depth = it->second.depth.size;
  out.labels = it->second.labels.size + it->second.labels_hi.size;
  out.color = it->second.color.size;
  out.masks = it->second.masks.size + it->second.masks_hi.size + it->second.segments.size;
  out.geometric = it->second.geometric.size;
  return out;
}

}  // namespace panmap
