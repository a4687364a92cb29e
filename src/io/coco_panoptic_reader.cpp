#include "panmap/io/coco_panoptic_reader.h"

#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "panmap/io/internal/json_file.h"

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/text_files.h"

namespace panmap {
namespace {

using nlohmann::json;

std::string stemOf(const std::string& file_name) {
  return std::filesystem::path(file_name).stem().string();
}

// segments_info entries -> segments with panmap classes. Unknown categories keep class 0.
std::vector<PanopticSegment> parseSegments(const json& info, const LabelTable& table,
                                           const std::string& what) {
  if (!info.is_array()) throw Error(what + ": segments_info must be a list");
  std::vector<PanopticSegment> segments;
  std::set<int32_t> ids;
  for (const json& s : info) {
    if (!s.is_object() || !s.contains("id") || !s.contains("category_id") ||
        !s["id"].is_number_integer() || !s["category_id"].is_number_integer()) {
      throw Error(what + ": a segments_info entry lacks integer id/category_id");
    }
    PanopticSegment seg;
    seg.id = s["id"].get<int32_t>();
    seg.source_category = s["category_id"].get<int32_t>();
    if (seg.id <= 0) throw Error(what + ": segment id " + std::to_string(seg.id) + " is not > 0");
    if (!ids.insert(seg.id).second) {
      throw Error(what + ": segment id " + std::to_string(seg.id) + " appears twice");
    }
    const auto entry = table.lookup(seg.source_category);
    if (entry) {
      seg.category = entry->panmap_class;
      seg.is_thing = entry->is_thing;
    } else {
      seg.category = 0;  // counted by the reader, with its category
    }
    if (s.contains("isthing")) {
      const json& isthing = s["isthing"];
      if (!isthing.is_boolean() && !isthing.is_number_integer()) {
        throw Error(what + ": isthing of segment " + std::to_string(seg.id) +
                    " is not 0/1 or true/false");
      }
      seg.is_thing = isthing.is_boolean() ? isthing.get<bool>() : isthing.get<long long>() != 0;
    }
    if (s.contains("score")) {
      if (!s["score"].is_number()) {
        throw Error(what + ": score of segment " + std::to_string(seg.id) + " is not a number");
      }
      const double score = s["score"].get<double>();
      if (!(score >= 0.0 && score <= 1.0)) {
        throw Error(what + ": score of segment " + std::to_string(seg.id) + " not in [0, 1]");
      }
      seg.score = static_cast<float>(score);
    }
    segments.push_back(seg);
  }
  return segments;
}

}  // namespace

CocoPanopticReader::CocoPanopticReader(const std::string& mask_dir, const std::string& json_path,
                                       LabelTable table)
    : mask_dir_(mask_dir), table_(std::move(table)) {
  if (!isDirectory(mask_dir)) throw Error("mask folder " + mask_dir + " does not exist");
  if (!json_path.empty()) {
    const json root = internal::readJsonFile(json_path);
    if (!root.is_object() || !root.contains("annotations") || !root["annotations"].is_array()) {
      throw Error(json_path + ": not a COCO panoptic file (no annotations list)");
    }
    // image_id -> image file stem; ids are integers in COCO, strings in Cityscapes' panoptic
    // files, so both are keyed by their text.
    std::map<std::string, std::string> image_names;
    auto idText = [&](const json& id, const std::string& where) {
      if (id.is_number_integer()) return std::to_string(id.get<long long>());
      if (id.is_string()) return id.get<std::string>();
      throw Error(json_path + ": " + where + " is neither an integer nor a string");
    };
    auto fileName = [&](const json& entry, const std::string& where) {
      if (!entry["file_name"].is_string()) {
        throw Error(json_path + ": " + where + "'s file_name is not a string");
      }
      return entry["file_name"].get<std::string>();
    };
    if (root.contains("images") && root["images"].is_array()) {
      for (const json& im : root["images"]) {
        if (im.is_object() && im.contains("id") && im.contains("file_name")) {
          image_names[idText(im["id"], "an image's id")] = stemOf(fileName(im, "an image"));
        }
      }
    }
    for (const json& a : root["annotations"]) {
      if (!a.contains("file_name") || !a.contains("segments_info")) {
        throw Error(json_path + ": an annotation lacks file_name or segments_info");
      }
      const std::string png = fileName(a, "an annotation");
      Entry entry;
      entry.png_path = mask_dir + "/" + png;
      entry.segments = parseSegments(a["segments_info"], table_, json_path + " (" + png + ")");
      std::string key = stemOf(png);
      if (a.contains("image_id")) {
        const auto it = image_names.find(idText(a["image_id"], "an annotation's image_id"));
        if (it != image_names.end()) key = it->second;
      }
      entries_[key] = entry;
    }
  } else {
    std::error_code ec;
    for (const auto& f : std::filesystem::directory_iterator(mask_dir, ec)) {
      if (f.path().extension() != ".png") continue;
      const std::string stem = f.path().stem().string();
      const std::string json_file = mask_dir + "/" + stem + ".json";
      if (!isRegularFile(json_file)) continue;
      entries_[stem] = Entry{f.path().string(), json_file, {}};
    }
  }
  if (entries_.empty()) {
    throw Error("mask folder " + mask_dir +
                " has no masks (PNG + JSON) in COCO panoptic format (class-id PNGs of a semantic "
                "network: panmap-import --masks-format semantic)");
  }
}

bool CocoPanopticReader::has(const std::string& color_stem) const {
  return entries_.count(color_stem) > 0;
}

PanopticFrame CocoPanopticReader::read(const std::string& color_stem) {
  const auto it = entries_.find(color_stem);
  if (it == entries_.end()) throw Error("no panoptic mask for colour image " + color_stem);
  const Entry& entry = it->second;
  PanopticFrame frame;
  if (!entry.json_path.empty()) {
    const json root = internal::readJsonFile(entry.json_path);
    const json& info =
        root.is_object() && root.contains("segments_info") ? root["segments_info"] : root;
    frame.segments = parseSegments(info, table_, entry.json_path);
  } else {
    frame.segments = entry.segments;
  }
  for (const auto& s : frame.segments) {
    if (table_.lookup(s.source_category)) continue;
    ++stats_.unknown_category_segments;
    ++stats_.unknown_category_ids[s.source_category];
  }
  const auto bytes = readFileBytes(entry.png_path);
  frame.segment_ids = decodeLabelPng(bytes.data(), bytes.size(), entry.png_path);
  // Pixels of ids without a segments_info entry are unsegmented (COCO: id 0 is void). They are
  // counted, and so are those a swap of R and B would have matched: cv2.imwrite of an RGB
  // array writes BGR, and left every pixel unlisted with nothing said.
  std::set<int32_t> known;
  for (const auto& s : frame.segments) known.insert(s.id);
  int32_t last_id = 0;
  bool last_known = true, last_bgr = false;
  for (size_t i = 0; i < frame.segment_ids.size(); ++i) {
    int32_t& id = frame.segment_ids.data()[i];
    if (id == 0) continue;
    ++stats_.labelled_pixels;
    if (id != last_id) {
      last_id = id;
      last_known = known.count(id) > 0;
      const int32_t swapped = (id >> 16 & 0xFF) | (id & 0xFF00) | (id & 0xFF) << 16;
      last_bgr = !last_known && known.count(swapped) > 0;
    }
    if (!last_known) {
      ++stats_.unlisted_pixels;
      stats_.unlisted_bgr_pixels += last_bgr ? 1 : 0;
      id = 0;
    }
  }
  ++stats_.frames_with_masks;
  stats_.segments += frame.segments.size();
  return frame;
}

}  // namespace panmap
