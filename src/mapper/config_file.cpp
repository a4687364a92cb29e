#include "panmap/mapper/config_file.h"

#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"

namespace panmap {
namespace {

// Reads the keys of one section, remembering which it consumed so the rest are reported.
class Section {
 public:
  Section(const cv::FileNode& node, std::string name, std::string file)
      : node_(node), name_(std::move(name)), file_(std::move(file)) {
    if (!node_.empty() && !node_.isMap()) fail(name_ + " must be a mapping");
  }
  template <typename T>
  void read(const char* key, T* value) {
    seen_.insert(key);
    const cv::FileNode n = node_[key];
    if (n.empty()) return;
    if constexpr (std::is_same<T, bool>::value) {
      // A switch: 0.5 became 0 and -1 became 1 when any number was taken.
      std::string word = n.isString() ? static_cast<std::string>(n) : "";
      word = word.substr(0, word.find('#'));
      word.erase(word.find_last_not_of(" \t") + 1);
      if (word == "true" || word == "false") {
        *value = word == "true";
        return;
      }
      if (!n.isInt() || (static_cast<int>(n) != 0 && static_cast<int>(n) != 1)) {
        fail(name_ + "." + key + " is a switch: 0 or 1 (or false / true)");
      }
      *value = static_cast<int>(n) == 1;
      return;
    }
    if (!n.isInt() && !n.isReal()) fail(name_ + "." + key + " must be a number");
    if constexpr (std::is_integral<T>::value) {
      if (!n.isInt()) fail(name_ + "." + key + " must be an integer");
      *value = static_cast<T>(static_cast<int>(n));
    } else {
      *value = static_cast<T>(static_cast<double>(n));
    }
  }
  /// A string value (quoted or not; OpenCV keeps a trailing comment in an unquoted one).
  void readString(const char* key, std::string* value) {
    seen_.insert(key);
    const cv::FileNode n = node_[key];
    if (n.empty()) return;
    if (!n.isString()) fail(name_ + "." + key + " must be a string");
    std::string text = static_cast<std::string>(n);
    text = text.substr(0, text.find('#'));
    text.erase(text.find_last_not_of(" \t") + 1);
    *value = text;
  }
  const cv::FileNode& node() const { return node_; }
  void markSeen(const char* key) { seen_.insert(key); }
  void finish() {
    if (node_.empty()) return;
    for (auto it = node_.begin(); it != node_.end(); ++it) {
      if (!seen_.count((*it).name())) fail("unknown key " + name_ + "." + (*it).name());
    }
  }
  [[noreturn]] void fail(const std::string& what) const { throw Error(file_ + ": " + what); }

 private:
  cv::FileNode node_;
  std::string name_;
  std::string file_;
  std::set<std::string> seen_;
};

// OpenCV's YAML reader (4.6) loops forever when a document's root collection ends before the
// end of the file and what follows does not start a new document ("%YAML:1.0\n m: 1\nma-- 3"
// hung fuzz/fuzz_config: the root mapping at column 1 ends at "ma--", the reader skips three
// characters and then spins on the "-"). A root block mapping at column 0 only ends at the end
// of the file or at a "..." line, so a config must be exactly that: one document whose first
// entry is a section name at column 0, with no "..." line. Control characters are refused as
// well: OpenCV measures lines with strlen, and a NUL byte on the header line led to the same
// loop. Checked before OpenCV parses the file.
// OpenCV's reader keeps the first of two equal keys in a mapping and drops the second without
// a word: a section appended to a printed config to override it did nothing. `open` holds the
// keys of the mappings enclosing this line, by indentation.
void checkDuplicateKey(const std::string& line, const std::string& where,
                       std::vector<std::pair<size_t, std::set<std::string>>>* open) {
  const size_t indent = line.find_first_not_of(' ');
  if (indent == std::string::npos || line[indent] == '#' || line[indent] == '-' || line[0] == '%' ||
      line.compare(0, 3, "---") == 0) {
    return;
  }
  const size_t colon = line.find(':', indent);
  if (colon == std::string::npos) return;
  std::string key = line.substr(indent, colon - indent);
  key.erase(key.find_last_not_of(' ') + 1);
  if (key.empty() || key.find_first_of(" \"'{}[],") != std::string::npos) return;
  while (!open->empty() && open->back().first > indent) open->pop_back();
  if (open->empty() || open->back().first < indent) open->push_back({indent, {}});
  if (!open->back().second.insert(key).second) {
    throw Error(where + "'" + key + "' appears twice in its mapping (the first would be used)");
  }
}

void checkConfigShape(const std::string& path, const std::string& text) {
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  bool root_seen = false;
  std::vector<std::pair<size_t, std::set<std::string>>> keys_by_indent;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string where = path + ":" + std::to_string(line_no) + ": ";
    for (size_t i = 0; i < line.size(); ++i) {
      const auto c = static_cast<unsigned char>(line[i]);
      if (c < 0x20 && c != '\t') {
        throw Error(where + "control character " + std::to_string(c) + " at column " +
                    std::to_string(i + 1));
      }
    }
    // YAML indents with spaces, and OpenCV's reader takes no tab before a comment either: it
    // failed naming one of its functions ("skipSpaces").
    const size_t tab = line.substr(0, line.find('#')).find('\t');
    if (tab != std::string::npos) {
      const bool indent = line.find_first_not_of(" \t") > tab;
      throw Error(
          where +
          (indent ? "a tab in the indentation" : "a tab at column " + std::to_string(tab + 1)) +
          " (a config takes spaces only)");
    }
    if (line.compare(0, 3, "...") == 0) {
      throw Error(where + "'...' ends the document; a config is one document without it");
    }
    checkDuplicateKey(line, where, &keys_by_indent);
    if (root_seen) continue;
    const size_t first = line.find_first_not_of(' ');
    if (first == std::string::npos || line[first] == '#' || line[0] == '%') continue;
    if (line.compare(0, 3, "---") == 0) {
      const size_t rest = line.find_first_not_of(' ', 3);
      if (rest != std::string::npos && line[rest] != '#') {
        throw Error(where + "nothing may follow '---' on its line");
      }
      continue;
    }
    const char c = line[0];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_')) {
      throw Error(where +
                  "expected a section name at column 0 (a config is a mapping of sections)");
    }
    root_seen = true;
  }
}

/// The YAML name of an energy weighting.
const char* weightingName(OptimiserConfig::Weighting weighting) {
  switch (weighting) {
    case OptimiserConfig::Weighting::kNone:
      return "none";
    case OptimiserConfig::Weighting::kShared:
      return "shared";
    case OptimiserConfig::Weighting::kSurface:
      break;
  }
  return "surface";
}

}  // namespace

std::string asConfigKeys(const std::string& message) {
  // The components' checks name their fields as the code does; a config's user knows the keys.
  static const std::pair<const char*, const char*> kNames[] = {
      {"OptimiserConfig.objects.", "objects."},
      {"OptimiserConfig.default_thresholds.", "optimiser."},
      {"OptimiserConfig.class_thresholds[", "optimiser.classes[class "},
      {"OptimiserConfig.", "optimiser."},
      {"SurfaceFusionConfig.", "fusion."},
      {"surface fusion ", "fusion."},
      {"superpoint ", "superpoints."},
      {"mapper num_threads", "threads"},
      {"integrator ", "integrator."},
      {"tracking ", "tracking."},
      {"occupancy ", "occupancy."},
      {"graph ", "graph."},
      {"sync ", "sync."}};
  for (const auto& [code, key] : kNames) {
    const std::string prefix = code;
    if (message.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = message.substr(prefix.size());
    // "integrator needs 0 <= min_depth_m ..." names no key: only a field name (with an
    // underscore) after "component " is one.
    if (prefix.back() == ' ' && rest.substr(0, rest.find(' ')).find('_') == std::string::npos) {
      return message;
    }
    return key + rest;
  }
  return message;
}

PanmapConfig loadConfig(const std::string& path) { return loadConfig(path, PanmapConfig{}); }

PanmapConfig loadConfig(const std::string& path, const PanmapConfig& base) {
  std::string text;
  {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw Error("config " + path + " is a folder");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error("cannot read config " + path);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (in.bad()) throw Error("cannot read config " + path);
  }
  checkConfigShape(path, text);
  // OpenCV reads YAML only after a "%YAML" directive on the first line, which plain YAML
  // leaves out: such a file was refused as "Input file is invalid". The directive is added
  // when the file has none; one below the first line is an error in YAML too.
  int added_lines = 0;
  if (text.compare(0, 5, "%YAML") != 0) {
    if (text.find("\n%YAML") != std::string::npos) {
      throw Error(path + ": the %YAML directive must be the first line");
    }
    text = "%YAML:1.0\n" + text;
    added_lines = 1;
  }
  cv::FileStorage fs;
  try {
    if (!fs.open(text,
                 cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML)) {
      throw Error("cannot read config " + path);
    }
  } catch (const cv::Exception& e) {
    // OpenCV's parser puts the line and the reason where the function's name would be,
    // "(3): Incorrect indentation", and its own function in err.
    std::smatch where;
    if (std::regex_match(e.func, where, std::regex(R"(\((\d+)\): (.*))"))) {
      const int line = std::stoi(where[1]) - added_lines;
      throw Error(path + ":" + std::to_string(line) + ": not a YAML config: " + where[2].str());
    }
    throw Error(path + ": not a YAML config (" + std::string(e.err) + ")");
  }
  PanmapConfig c = base;
  MapperConfig& m = c.mapper;
  const cv::FileNode root = fs.root();
  const std::set<std::string> sections = {"map",       "integrator",  "depth_segmentation",
                                          "fusion",    "superpoints", "graph",
                                          "occupancy", "tracking",    "optimiser",
                                          "objects",   "threads",     "depth_calibration",
                                          "sync"};
  for (auto it = root.begin(); it != root.end(); ++it) {
    if (!sections.count((*it).name())) throw Error(path + ": unknown section " + (*it).name());
  }
  {
    Section s(root["map"], "map", path);
    s.read("voxel_size_m", &m.map.voxel_size_m);
    s.finish();
  }
  {
    Section s(root["integrator"], "integrator", path);
    s.read("truncation_voxels", &m.integrator.truncation_voxels);
    s.read("max_weight", &m.integrator.max_weight);
    s.read("min_depth_m", &m.integrator.min_depth_m);
    s.read("max_depth_m", &m.integrator.max_depth_m);
    s.read("weight_dropoff", &m.integrator.weight_dropoff);
    s.read("space_carving", &m.integrator.space_carving);
    s.read("vote_stride_px", &m.integrator.vote_stride_px);
    s.finish();
  }
  {
    Section s(root["depth_segmentation"], "depth_segmentation", path);
    s.read("normals_window_px", &m.depth_segmentation.normals_window_px);
    s.read("min_convexity_window_px", &m.depth_segmentation.min_convexity_window_px);
    s.read("min_convexity_threshold", &m.depth_segmentation.min_convexity_threshold);
    s.read("depth_discontinuity_ratio", &m.depth_segmentation.depth_discontinuity_ratio);
    s.read("min_segment_px", &m.depth_segmentation.min_segment_px);
    s.read("max_depth_m", &m.depth_segmentation.max_depth_m);
    s.finish();
  }
  {
    Section s(root["fusion"], "fusion", path);
    s.read("min_surface_px", &m.fusion.min_surface_px);
    s.read("stuff_confidence", &m.fusion.stuff_confidence);
    s.read("geometry_only", &m.fusion.geometry_only);
    s.read("mask_only_surfaces", &m.fusion.mask_only_surfaces);
    s.read("mask_only_depth_step", &m.fusion.mask_only_depth_step);
    s.read("fill_mask_edges", &m.mask_edge_fill.enabled);
    s.read("fill_max_depth_step", &m.mask_edge_fill.max_depth_step);
    s.read("fill_max_distance_px", &m.mask_edge_fill.max_distance_px);
    s.finish();
  }
  {
    Section s(root["superpoints"], "superpoints", path);
    s.read("association_min_overlap", &m.superpoints.association_min_overlap);
    s.read("significant_overlap", &m.superpoints.significant_overlap);
    s.read("merge_threshold", &m.superpoints.merge_threshold);
    s.read("semantic_consistency", &m.superpoints.semantic_consistency);
    s.read("sample_stride_px", &m.superpoints.sample_stride_px);
    s.read("instance_min_overlap", &m.superpoints.instance_min_overlap);
    s.read("mask_verdicts", &m.superpoints.mask_verdicts);
    s.read("apart_weight", &m.superpoints.apart_weight);
    s.read("join_mask_pieces", &m.superpoints.join_mask_pieces);
    s.read("revisit_votes", &m.superpoints.revisit_votes);
    s.finish();
  }
  {
    Section s(root["graph"], "graph", path);
    s.read("spatial_scale_m", &m.graph.spatial_scale_m);
    s.read("sample_stride_px", &m.graph.sample_stride_px);
    s.read("prune_edges", &m.graph.prune_edges);
    s.read("edge_min_share", &m.graph.edge_min_share);
    s.read("surface_band_voxels", &m.graph.surface_band_voxels);
    s.read("pair_interior_px", &m.graph.pair_interior_px);
    s.finish();
  }
  {
    Section s(root["occupancy"], "occupancy", path);
    s.read("enabled", &m.occupancy_enabled);
    s.read("resolution_m", &m.occupancy.resolution_m);
    s.read("min_depth_m", &m.occupancy.min_depth_m);
    s.read("max_depth_m", &m.occupancy.max_depth_m);
    s.read("pixel_stride", &m.occupancy.pixel_stride);
    s.read("prob_hit", &m.occupancy.prob_hit);
    s.read("prob_miss", &m.occupancy.prob_miss);
    s.read("clamping_min", &m.occupancy.clamping_min);
    s.read("clamping_max", &m.occupancy.clamping_max);
    s.read("occupancy_threshold", &m.occupancy.occupancy_threshold);
    s.finish();
  }
  {
    FrameToModelAligner::Config& t = m.tracking;
    Section s(root["tracking"], "tracking", path);
    // A word value, or "" when the key is absent.
    auto word = [&s](const char* key) {
      s.markSeen(key);
      const cv::FileNode node = s.node().empty() ? cv::FileNode() : s.node()[key];
      if (node.empty()) return std::string();
      std::string text = node.isString() ? static_cast<std::string>(node) : "?";
      // OpenCV keeps a trailing comment as part of an unquoted string.
      text = text.substr(0, text.find('#'));
      text.erase(text.find_last_not_of(" \t") + 1);
      return text;
    };
    const std::string mode = word("mode");
    if (mode == "off") {
      m.tracking_mode = MapperConfig::TrackingMode::kOff;
    } else if (mode == "auto") {
      m.tracking_mode = MapperConfig::TrackingMode::kAuto;
    } else if (mode == "on") {
      m.tracking_mode = MapperConfig::TrackingMode::kOn;
    } else if (!mode.empty()) {
      s.fail("tracking.mode must be off, auto or on, not \"" + mode + "\"");
    }
    const std::string correction = word("correction");
    if (correction == "per_frame") {
      m.tracking_correction = MapperConfig::PoseCorrection::kPerFrame;
    } else if (correction == "filter") {
      // The aligner's defaults follow the model; keys below override them.
      m.tracking_correction = MapperConfig::PoseCorrection::kFilter;
      t = FrameToModelAligner::Config::forDriftFilter();
    } else if (!correction.empty()) {
      s.fail("tracking.correction must be per_frame or filter, not \"" + correction + "\"");
    }
    s.read("warmup_frames", &m.tracking_warmup_frames);
    s.read("depth_check_frames", &m.depth_check.frames);
    s.read("max_depth_pattern_m", &m.depth_check.max_pattern_m);
    s.read("max_iterations", &t.max_iterations);
    s.read("robust_scale_m", &t.robust_scale_m);
    s.read("point_sigma_m", &t.point_sigma_m);
    s.read("depth_noise_at_1m_m", &t.depth_noise_at_1m_m);
    s.read("min_depth_m", &t.min_depth_m);
    s.read("max_depth_m", &t.max_depth_m);
    s.read("prior_sigma_translation_m", &t.prior_sigma_translation_m);
    s.read("prior_sigma_rotation_rad", &t.prior_sigma_rotation_rad);
    s.read("min_points", &t.min_points);
    s.read("inlier_distance_m", &t.inlier_distance_m);
    s.read("min_inlier_ratio", &t.min_inlier_ratio);
    s.read("min_relative_eigenvalue", &t.min_relative_eigenvalue);
    s.read("weak_direction_damping", &t.weak_direction_damping);
    s.read("remap_degenerate", &t.remap_degenerate);
    s.read("max_correction_translation_m", &t.max_correction_translation_m);
    s.read("max_correction_rotation_rad", &t.max_correction_rotation_rad);
    DriftFilter::Config& d = m.drift;
    s.read("drift_per_m", &d.drift_per_m);
    s.read("drift_deg_per_m", &d.drift_deg_per_m);
    s.read("drift_deg_per_90deg", &d.drift_deg_per_90deg);
    s.read("drift_correlation_m", &d.correlation_m);
    s.read("measurement_sigma_m", &d.measurement_sigma_m);
    s.read("measurement_sigma_deg", &d.measurement_sigma_deg);
    s.finish();
  }
  {
    SyncConfig& y = c.sync;
    Section s(root["sync"], "sync", path);
    // Times in the units a user thinks in; kept in microseconds. Out of range is refused here,
    // before the conversion: a negative or huge value is a typo, not a setting.
    auto readTime = [&](const char* key, double unit_us, double max, int64_t* us) {
      double value = static_cast<double>(*us) / unit_us;
      s.read(key, &value);
      if (!(value >= 0.0 && value <= max)) {
        std::ostringstream why;
        why << "sync." << key << " must be in [0, " << max << "]";
        s.fail(why.str());
      }
      *us = static_cast<int64_t>(std::llround(value * unit_us));
    };
    readTime("pose_tolerance_ms", 1e3, 1e6, &y.pose_tolerance_us);
    readTime("max_pose_gap_ms", 1e3, 1e6, &y.max_pose_gap_us);
    readTime("mask_tolerance_ms", 1e3, 1e6, &y.mask_tolerance_us);
    readTime("wait_s", 1e6, 3600.0, &y.wait_us);
    s.read("masks_in_order", &y.masks_in_order);
    int max_queue = static_cast<int>(y.max_queue);
    s.read("max_queue", &max_queue);
    if (max_queue < 1 || max_queue > 100000) s.fail("sync.max_queue must be in [1, 100000]");
    y.max_queue = static_cast<size_t>(max_queue);
    s.finish();
  }
  {
    OptimiserConfig& o = c.optimiser;
    Section s(root["optimiser"], "optimiser", path);
    s.read("regularise", &o.regularise);
    s.read("refine", &o.refine);
    s.read("class_consensus", &o.class_consensus);
    s.read("consensus_min_ratio", &o.consensus_min_ratio);
    s.read("K_C", &o.K_C);
    s.read("theta", &o.theta);
    s.read("max_sweeps", &o.max_sweeps);
    s.read("discount_apart", &o.discount_apart);
    std::string weighting = weightingName(o.weighting);
    s.readString("weighting", &weighting);
    if (weighting == "none") {
      o.weighting = OptimiserConfig::Weighting::kNone;
    } else if (weighting == "surface") {
      o.weighting = OptimiserConfig::Weighting::kSurface;
    } else if (weighting == "shared") {
      o.weighting = OptimiserConfig::Weighting::kShared;
    } else {
      s.fail("optimiser.weighting must be surface, shared or none, not \"" + weighting + "\"");
    }
    std::string link_scale =
        o.link_scale == OptimiserConfig::LinkScale::kGeometric ? "geometric" : "smaller";
    s.readString("link_scale", &link_scale);
    if (link_scale != "smaller" && link_scale != "geometric") {
      s.fail("optimiser.link_scale must be smaller or geometric, not \"" + link_scale + "\"");
    }
    o.link_scale = link_scale == "geometric" ? OptimiserConfig::LinkScale::kGeometric
                                             : OptimiserConfig::LinkScale::kSmaller;
    s.read("link_half_observations", &o.link_half_observations);
    s.read("max_void_share", &o.max_void_share);
    std::string refinement =
        o.refinement == OptimiserConfig::Refinement::kPaperRules ? "paper" : "clustering";
    s.readString("refinement", &refinement);
    if (refinement != "clustering" && refinement != "paper") {
      s.fail("optimiser.refinement must be clustering or paper");
    }
    o.refinement = refinement == "paper" ? OptimiserConfig::Refinement::kPaperRules
                                         : OptimiserConfig::Refinement::kClustering;
    s.read("join_affinity", &o.join_affinity);
    s.read("min_coverage", &o.min_coverage);
    s.read("theta_D", &o.default_thresholds.theta_D);
    s.read("theta_O", &o.default_thresholds.theta_O);
    s.read("theta_L", &o.default_thresholds.theta_L);
    s.markSeen("classes");
    const cv::FileNode classes = s.node().empty() ? cv::FileNode() : s.node()["classes"];
    if (!classes.empty()) {
      if (!classes.isSeq()) s.fail("optimiser.classes must be a list");
      for (auto it = classes.begin(); it != classes.end(); ++it) {
        Section entry(*it, "optimiser.classes[]", path);
        int32_t cls = -1;
        OptimiserConfig::Thresholds t = o.default_thresholds;
        entry.read("class", &cls);
        entry.read("theta_D", &t.theta_D);
        entry.read("theta_O", &t.theta_O);
        entry.read("theta_L", &t.theta_L);
        entry.finish();
        if (cls <= 0 || cls > kMaxNyu40Class) {
          entry.fail("optimiser.classes[] needs a class of 1..40 (NYU40), not " +
                     std::to_string(cls));
        }
        // A class given twice kept the later entry silently.
        if (!o.class_thresholds.emplace(cls, t).second) {
          entry.fail("optimiser.classes[] lists class " + std::to_string(cls) + " twice");
        }
      }
    }
    s.finish();
  }
  {
    OptimiserConfig::Objects& o = c.optimiser.objects;
    Section s(root["objects"], "objects", path);
    s.read("consolidate", &o.consolidate);
    s.read("min_area_m2", &o.min_area_m2);
    s.read("confidence_bias", &o.bias);
    s.read("confidence_area", &o.area);
    s.read("confidence_support", &o.support);
    s.read("confidence_share", &o.share);
    s.finish();
  }
  if (!root["threads"].empty()) {
    if (!root["threads"].isInt()) throw Error(path + ": threads must be an integer");
    m.num_threads = static_cast<int>(root["threads"]);
  }
  if (!root["depth_calibration"].empty()) {
    if (!root["depth_calibration"].isString()) {
      throw Error(path + ": depth_calibration must be a file name");
    }
    std::string file = static_cast<std::string>(root["depth_calibration"]);
    file = file.substr(0, file.find('#'));  // OpenCV keeps a trailing comment in the string
    file.erase(file.find_last_not_of(" \t") + 1);
    // A relative name is relative to the config's folder, so configs and calibrations travel
    // together.
    const std::filesystem::path p(file);
    const std::filesystem::path resolved =
        p.is_absolute() ? p : std::filesystem::path(path).parent_path() / p;
    m.depth_calibration_file = std::filesystem::absolute(resolved).lexically_normal().string();
    try {
      m.depth_calibration = std::make_shared<const DepthCalibration>(
          DepthCalibration::load(m.depth_calibration_file));
    } catch (const Error& e) {
      throw Error(path + ": " + e.what());
    }
  }
  // One key for both: III-B must not merge into a super-point the final labelling leaves
  // unlabelled (SuperpointConfig::unlabelled_void_share).
  c.mapper.superpoints.unlabelled_void_share = c.optimiser.max_void_share;
  try {
    c.optimiser.check();  // first: a bad max_void_share is named by its own key
    c.mapper.check();
  } catch (const Error& e) {
    throw Error(path + ": " + asConfigKeys(e.what()));
  }
  return c;
}

std::string configToYaml(const PanmapConfig& c) {
  const MapperConfig& m = c.mapper;
  std::ostringstream y;
  y << "%YAML:1.0\n---\n# panmap configuration. Every key is optional; missing keys keep these "
       "defaults.\n";
  y << "map:\n   voxel_size_m: " << m.map.voxel_size_m << "   # voxel edge, metres\n";
  y << "integrator:\n"
    << "   truncation_voxels: " << m.integrator.truncation_voxels
    << "   # TSDF truncation, voxels\n"
    << "   max_weight: " << m.integrator.max_weight << "   # weights saturate here\n"
    << "   min_depth_m: " << m.integrator.min_depth_m << "   # depth range used, metres\n"
    << "   max_depth_m: " << m.integrator.max_depth_m << "\n"
    << "   weight_dropoff: " << m.integrator.weight_dropoff
    << "   # weight falls behind the surface (0/1)\n"
    << "   space_carving: " << m.integrator.space_carving
    << "   # record free space up to the camera (0/1)\n"
    << "   vote_stride_px: " << m.integrator.vote_stride_px
    << "   # pixels between label votes (0 = automatic by voxel size)\n";
  y << "depth_segmentation:\n"
    << "   normals_window_px: " << m.depth_segmentation.normals_window_px << "\n"
    << "   min_convexity_window_px: " << m.depth_segmentation.min_convexity_window_px << "\n"
    << "   min_convexity_threshold: " << m.depth_segmentation.min_convexity_threshold << "\n"
    << "   depth_discontinuity_ratio: " << m.depth_segmentation.depth_discontinuity_ratio << "\n"
    << "   min_segment_px: " << m.depth_segmentation.min_segment_px << "\n"
    << "   max_depth_m: " << m.depth_segmentation.max_depth_m << "\n";
  y << "fusion:\n"
    << "   min_surface_px: " << m.fusion.min_surface_px << "   # smaller surfaces are dropped\n"
    << "   stuff_confidence: " << m.fusion.stuff_confidence << "   # P_o of stuff (Eq. 1)\n"
    << "   geometry_only: " << m.fusion.geometry_only << "   # ignore panoptic masks (0/1)\n"
    << "   mask_only_surfaces: " << m.fusion.mask_only_surfaces
    << "   # a thing mask with no geometric segment (small, far) votes with its own pixels (0/1)\n"
    << "   mask_only_depth_step: " << m.fusion.mask_only_depth_step
    << "   # ... split where the depth steps by more than this share\n"
    << "   fill_mask_edges: " << m.mask_edge_fill.enabled
    << "   # a mask's pixels outside every surface (edges, thin parts) vote with its surfaces "
       "(0/1)\n"
    << "   fill_max_depth_step: " << m.mask_edge_fill.max_depth_step
    << "   # ... across depth steps up to this share of the depth\n"
    << "   fill_max_distance_px: " << m.mask_edge_fill.max_distance_px
    << "   # ... at most this many pixels from a labelled one (0: no limit)\n";
  y << "superpoints:\n"
    << "   association_min_overlap: " << m.superpoints.association_min_overlap << "\n"
    << "   significant_overlap: " << m.superpoints.significant_overlap << "   # L_N(s_i) share\n"
    << "   merge_threshold: " << m.superpoints.merge_threshold << "   # theta_merge\n"
    << "   semantic_consistency: " << m.superpoints.semantic_consistency
    << "   # 0: spatial-only merging\n"
    << "   sample_stride_px: " << m.superpoints.sample_stride_px << "\n"
    << "   instance_min_overlap: " << m.superpoints.instance_min_overlap << "\n"
    << "   mask_verdicts: " << m.superpoints.mask_verdicts
    << "   # 1: only masks of their class merge or split super-points\n"
    << "   apart_weight: " << m.superpoints.apart_weight
    << "   # merge only when co-observed in more than this x the frames showing two objects\n"
    << "   join_mask_pieces: " << m.superpoints.join_mask_pieces
    << "   # 1: pieces of one mask share the super-point of its class\n"
    << "   revisit_votes: " << m.superpoints.revisit_votes
    << "   # 1: a surface takes back its class's super-point from its voxels' votes\n";
  y << "graph:\n"
    << "   spatial_scale_m: " << m.graph.spatial_scale_m << "   # P_s = 1 / (1 + d / scale)\n"
    << "   sample_stride_px: " << m.graph.sample_stride_px << "\n"
    << "   prune_edges: " << m.graph.prune_edges
    << "   # keep edges only between touching or strongly co-observed surface owners\n"
    << "   edge_min_share: " << m.graph.edge_min_share
    << "   # strong: P_eps or P_sep >= share x the smaller sum of P_nu\n"
    << "   surface_band_voxels: " << m.graph.surface_band_voxels
    << "   # |sdf| band of the surface\n"
    << "   pair_interior_px: " << m.graph.pair_interior_px
    << "   # co-observation counts pixels this far inside a mask's outline (0: all)\n";
  const OccupancyMap::Config& oc = m.occupancy;
  y << "occupancy:\n"
    << "   enabled: " << m.occupancy_enabled << "   # OctoMap tree for planners (0/1)\n"
    << "   resolution_m: " << oc.resolution_m << "   # cell edge, metres\n"
    << "   min_depth_m: " << oc.min_depth_m << "\n"
    << "   max_depth_m: " << oc.max_depth_m << "   # free space reaches this far, metres\n"
    << "   pixel_stride: " << oc.pixel_stride << "   # pixels between hits\n"
    << "   prob_hit: " << oc.prob_hit << "\n"
    << "   prob_miss: " << oc.prob_miss << "\n"
    << "   clamping_min: " << oc.clamping_min << "\n"
    << "   clamping_max: " << oc.clamping_max << "\n"
    << "   occupancy_threshold: " << oc.occupancy_threshold << "\n";
  const FrameToModelAligner::Config& t = m.tracking;
  const char* mode = m.tracking_mode == MapperConfig::TrackingMode::kOff  ? "off"
                     : m.tracking_mode == MapperConfig::TrackingMode::kOn ? "on"
                                                                          : "auto";
  y << "tracking:\n"
    << "   mode: \"" << mode
    << "\"   # refine poses against the map - off, auto (SLAM or odometry poses) or on\n"
    << "   warmup_frames: " << m.tracking_warmup_frames << "   # frames mapped before refining\n"
    << "   depth_check_frames: " << m.depth_check.frames
    << "   # auto: aligned frames that judge the depth before poses are corrected (0: trust it)\n"
    << "   max_depth_pattern_m: " << m.depth_check.max_pattern_m
    << "   # auto: a fixed depth error pattern above this keeps every pose as given\n"
    << "   correction: \""
    << (m.tracking_correction == MapperConfig::PoseCorrection::kFilter ? "filter" : "per_frame")
    << "\"   # per_frame (aligned pose used as is) or filter (smooth drift estimate, "
       "docs/MAPPING.md)\n"
    << "   max_iterations: " << t.max_iterations << "   # per pyramid level\n"
    << "   robust_scale_m: " << t.robust_scale_m << "   # Huber scale, metres\n"
    << "   point_sigma_m: " << t.point_sigma_m << "   # a point's error at the best depth\n"
    << "   depth_noise_at_1m_m: " << t.depth_noise_at_1m_m
    << "   # sensor depth noise at 1 m, grows with z^2 (0: every point alike)\n"
    << "   min_depth_m: " << t.min_depth_m << "\n"
    << "   max_depth_m: " << t.max_depth_m << "\n"
    << "   prior_sigma_translation_m: " << t.prior_sigma_translation_m
    << "   # prior on one alignment's increment (per_frame 0.01: frame-to-frame error; filter "
       "0.05)\n"
    << "   prior_sigma_rotation_rad: " << t.prior_sigma_rotation_rad << "\n"
    << "   min_points: " << t.min_points << "\n"
    << "   inlier_distance_m: " << t.inlier_distance_m << "\n"
    << "   min_inlier_ratio: " << t.min_inlier_ratio << "\n"
    << "   min_relative_eigenvalue: " << t.min_relative_eigenvalue
    << "   # below: an unconstrained direction\n"
    << "   weak_direction_damping: " << t.weak_direction_damping
    << "   # extra prior, share of the strongest direction's information (0: off)\n"
    << "   remap_degenerate: " << t.remap_degenerate
    << "   # correct only constrained directions (0: refuse)\n"
    << "   max_correction_translation_m: " << t.max_correction_translation_m << "\n"
    << "   max_correction_rotation_rad: " << t.max_correction_rotation_rad << "\n"
    << "   drift_per_m: " << m.drift.drift_per_m
    << "   # drift the input may have: per metre travelled (random walk)\n"
    << "   drift_deg_per_m: " << m.drift.drift_deg_per_m << "\n"
    << "   drift_deg_per_90deg: " << m.drift.drift_deg_per_90deg << "   # per 90 degrees turned\n"
    << "   drift_correlation_m: " << m.drift.correlation_m
    << "   # the drift rate holds over this distance\n"
    << "   measurement_sigma_m: " << m.drift.measurement_sigma_m
    << "   # floor of one frame alignment's error\n"
    << "   measurement_sigma_deg: " << m.drift.measurement_sigma_deg << "\n";
  const OptimiserConfig& o = c.optimiser;
  y << "optimiser:\n"
    << "   regularise: " << o.regularise << "   # III-C alpha-beta swap (0/1)\n"
    << "   refine: " << o.refine << "   # III-D instance refinement (0/1)\n"
    << "   class_consensus: " << o.class_consensus
    << "   # III-C: one class per group the network showed as one object (0/1)\n"
    << "   consensus_min_ratio: " << o.consensus_min_ratio
    << "   # a super-point takes the group's class if its own score for it is this share of its "
       "own class's\n"
    << "   K_C: " << o.K_C << "\n"
    << "   theta: " << o.theta << "\n"
    << "   max_sweeps: " << o.max_sweeps << "\n"
    << "   discount_apart: " << o.discount_apart
    << "   # Eq. 9 co-observation times P_eps / (P_eps + P_apart) (0/1)\n"
    << "   weighting: \"" << weightingName(o.weighting)
    << "\"   # Eq. 7 terms per voxel (surface; shared: edges split each super-point's voxels)"
       " or per super-point and edge (none, the paper)\n"
    << "   link_scale: \""
    << (o.link_scale == OptimiserConfig::LinkScale::kGeometric ? "geometric" : "smaller")
    << "\"   # Eq. 9 co-observation over the smaller (smaller) or geometric mean (geometric) of"
       " the two score sums\n"
    << "   link_half_observations: " << o.link_half_observations
    << "   # a link counts n / (n + this), n its less observed end's observations per voxel\n"
    << "   max_void_share: " << o.max_void_share
    << "   # super-points no mask covered in more of their frames stay unlabelled (1: off)\n"
    << "   refinement: \""
    << (o.refinement == OptimiserConfig::Refinement::kPaperRules ? "paper" : "clustering")
    << "\"   # III-D: clustering by one-mask / two-mask evidence, or the paper's rules\n"
    << "   join_affinity: " << o.join_affinity
    << "   # clustering: join when P_eps / (P_eps + P_sep) reaches this\n"
    << "   min_coverage: " << o.min_coverage
    << "   # clustering: and P_eps reaches this share of the smaller one's P_nu\n"
    << "   theta_D: " << o.default_thresholds.theta_D << "   # defaults for classes not listed\n"
    << "   theta_O: " << o.default_thresholds.theta_O << "\n"
    << "   theta_L: " << o.default_thresholds.theta_L << "\n";
  y << "   classes:\n";
  for (const auto& [cls, t] : o.class_thresholds) {
    y << "      - { class: " << cls << ", theta_D: " << t.theta_D << ", theta_O: " << t.theta_O
      << ", theta_L: " << t.theta_L << " }\n";
  }
  if (o.class_thresholds.empty()) y << "      []\n";
  const OptimiserConfig::Objects& ob = o.objects;
  y << "objects:\n"
    << "   consolidate: " << ob.consolidate
    << "   # fold fragments into their neighbours or leave them out (0/1)\n"
    << "   min_area_m2: " << ob.min_area_m2 << "   # smaller instances are fragments\n"
    << "   confidence_bias: " << ob.bias
    << "   # confidence = logistic(bias + area log10(m2) + support log2(obs/voxel) + share)\n"
    << "   confidence_area: " << ob.area << "\n"
    << "   confidence_support: " << ob.support << "\n"
    << "   confidence_share: " << ob.share << "\n";
  const SyncConfig& sy = c.sync;
  y << "sync:   # how frames, poses and masks arriving apart are matched (live and offline)\n"
    << "   pose_tolerance_ms: " << sy.pose_tolerance_us * 1e-3
    << "   # a pose this near a frame's utime is taken as it is\n"
    << "   max_pose_gap_ms: " << sy.max_pose_gap_us * 1e-3
    << "   # poses this far apart or nearer are interpolated at the frame's utime\n"
    << "   mask_tolerance_ms: " << sy.mask_tolerance_us * 1e-3
    << "   # a mask goes with the frame nearest its utime within this\n"
    << "   wait_s: " << sy.wait_us * 1e-6
    << "   # how long a frame waits for its mask (then mapped without) and its pose (then "
       "refused), by the newest utime received\n"
    << "   masks_in_order: " << sy.masks_in_order
    << "   # the network sends masks in frame order: a later frame's mask ends the wait (0/1)\n"
    << "   max_queue: " << sy.max_queue
    << "   # frames waiting at most; the oldest then goes on without its mask\n";
  y << "threads: " << m.num_threads << "\n";
  if (m.hasDepthCalibration()) {
    y << "depth_calibration: \"" << m.depth_calibration_file
      << "\"   # the depth sensor's calibration (panmap-calibrate-depth)\n";
  } else {
    y << "# depth_calibration: \"FILE\"   # a depth sensor's calibration from "
         "panmap-calibrate-depth\n";
  }
  return y.str();
}

namespace {

// A YAML line's key and value, comment and indentation left out.
std::pair<std::string, std::string> keyAndValue(const std::string& line) {
  const std::string text = line.substr(0, line.find('#'));
  const size_t colon = text.find(':');
  auto trim = [](std::string v) {
    v.erase(0, v.find_first_not_of(' '));
    v.erase(v.find_last_not_of(' ') + 1);
    return v;
  };
  if (colon == std::string::npos) return {trim(text), ""};
  return {trim(text.substr(0, colon)), trim(text.substr(colon + 1))};
}

}  // namespace

SettingDifference mapperSettingDifference(const MapperConfig& have, const MapperConfig& wanted) {
  // Both printed with one optimiser, so that only the mapper's settings can differ; the
  // printed values are what a user wrote and would recognise.
  const PanmapConfig a{have, OptimiserConfig{}, SyncConfig{}};
  const PanmapConfig b{wanted, OptimiserConfig{}, SyncConfig{}};
  std::istringstream in_a(configToYaml(a)), in_b(configToYaml(b));
  std::string line_a, line_b, section;
  while (std::getline(in_a, line_a) && std::getline(in_b, line_b)) {
    if (!line_a.empty() && line_a[0] != ' ' && line_a[0] != '#' && line_a[0] != '%') {
      section = keyAndValue(line_a).first;
    }
    if (line_a == line_b) continue;
    if (line_a.empty() || line_b.empty()) return {section, "?", "?"};
    // The depth calibration is a commented-out line when there is none.
    const bool none_a = line_a[0] == '#', none_b = line_b[0] == '#';
    const auto [key, value_a] = keyAndValue(none_a ? line_a.substr(1) : line_a);
    const std::string value_b = keyAndValue(none_b ? line_b.substr(1) : line_b).second;
    const bool top_level = line_a[0] != ' ';
    return {top_level ? key : section + "." + key, none_a ? "none" : value_a,
            none_b ? "none" : value_b};
  }
  return {};
}

}  // namespace panmap
