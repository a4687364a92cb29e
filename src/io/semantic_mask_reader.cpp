#include "panmap/io/semantic_mask_reader.h"

#include <filesystem>
#include <set>
#include <unordered_map>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "panmap/core/error.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/opencv_image.h"
#include "panmap/io/text_files.h"

namespace panmap {

namespace {

// A PNG's colour type (IHDR byte 25): 0 is greyscale; colour and palette images would decode
// to colours, not to the class ids a palette indexes.
constexpr size_t kPngColourTypeByte = 25;

}  // namespace

bool isSemanticVoid(int32_t id, const LabelTable& table) {
  return (id == 0 || id == 255 || id == 65535) && !table.lookup(id);
}

PanopticFrame panopticFromClasses(const LabelImage& classes, const LabelTable& table,
                                  size_t* unknown_ids, std::map<int32_t, size_t>* unknown_by_id,
                                  std::set<int32_t>* void_ids) {
  std::set<int32_t> present;
  const int32_t* pixel = classes.data();
  for (size_t i = 0; i < classes.size(); ++i) {
    if (i == 0 || pixel[i] != pixel[i - 1]) present.insert(pixel[i]);  // runs: one insert each
  }
  PanopticFrame frame;
  frame.segment_ids = LabelImage(classes.width(), classes.height(), 0);
  const cv::Mat class_mat = asMat(classes);
  cv::Mat region, components;
  int32_t next_id = 1;
  for (const int32_t source : present) {
    const auto entry = table.lookup(source);
    // Void counted as an unknown category made the import suggest --contiguous-ids, which
    // would have given 0's pixels the class of the table's first row.
    if (isSemanticVoid(source, table)) {
      if (void_ids) void_ids->insert(source);
      continue;
    }
    if (!entry) {
      ++*unknown_ids;
      if (unknown_by_id) ++(*unknown_by_id)[source];
      continue;
    }
    region = class_mat == source;
    // Stuff is one region whatever its shape; things are split where they do not touch.
    int regions = 1;
    if (entry->is_thing) {
      regions = cv::connectedComponents(region, components, 8, CV_32S) - 1;
    } else {
      region.convertTo(components, CV_32S, 1.0 / 255.0);
    }
    for (int v = 0; v < classes.height(); ++v) {
      const int32_t* in = components.ptr<int32_t>(v);
      int32_t* out = frame.segment_ids.row(v);
      for (int u = 0; u < classes.width(); ++u) {
        if (in[u] > 0) out[u] = next_id + in[u] - 1;
      }
    }
    for (int k = 0; k < regions; ++k) {
      frame.segments.push_back(
          PanopticSegment{next_id + k, entry->panmap_class, source, entry->is_thing, 1.0f});
    }
    next_id += regions;
  }
  return frame;
}

PanopticFrame withoutInstances(const PanopticFrame& panoptic, const LabelTable& table) {
  std::unordered_map<int32_t, int32_t> class_of;
  for (const PanopticSegment& s : panoptic.segments) class_of[s.id] = s.category;
  LabelImage classes(panoptic.segment_ids.width(), panoptic.segment_ids.height(), 0);
  for (size_t i = 0; i < classes.size(); ++i) {
    const auto it = class_of.find(panoptic.segment_ids.data()[i]);
    if (it != class_of.end()) classes.data()[i] = it->second;
  }
  size_t unknown = 0;
  PanopticFrame semantic = panopticFromClasses(classes, table, &unknown);
  semantic.utime = panoptic.utime;
  semantic.frame_id = panoptic.frame_id;
  return semantic;
}

SemanticMaskReader::SemanticMaskReader(const std::string& mask_dir, LabelTable table)
    : table_(std::move(table)) {
  if (!isDirectory(mask_dir)) throw Error("mask folder " + mask_dir + " does not exist");
  std::error_code ec;
  for (const auto& f : std::filesystem::directory_iterator(mask_dir, ec)) {
    if (f.path().extension() == ".png") files_[f.path().stem().string()] = f.path().string();
  }
  if (files_.empty()) throw Error("mask folder " + mask_dir + " has no PNG masks");
}

bool SemanticMaskReader::has(const std::string& color_stem) const {
  return files_.count(color_stem) > 0;
}

PanopticFrame SemanticMaskReader::read(const std::string& color_stem) {
  const auto it = files_.find(color_stem);
  if (it == files_.end()) throw Error("no semantic mask for colour image " + color_stem);
  const std::string& path = it->second;
  const auto bytes = readFileBytes(path);
  // Anything but a PNG is left to decodeLabelPng, whose error says it is not one.
  if (isPng(bytes.data(), bytes.size()) && bytes.size() > kPngColourTypeByte &&
      bytes[kPngColourTypeByte] != 0) {
    throw Error(path +
                ": a semantic mask must be a greyscale PNG of class ids (8 or 16 bit), "
                "not a colour or palette image");
  }
  const LabelImage classes = decodeLabelPng(bytes.data(), bytes.size(), path);
  size_t unknown = 0;
  PanopticFrame frame = panopticFromClasses(classes, table_, &unknown, &stats_.unknown_category_ids,
                                            &stats_.void_ids);
  ++stats_.frames_with_masks;
  stats_.segments += frame.segments.size();
  stats_.unknown_category_segments += unknown;
  return frame;
}

}  // namespace panmap
