// Bytes per frame and add / load times of the loop-closure frame store (docs/LOOP_CLOSURE.md,
// repair step 1; issue 22's budget: <= 150 kB per frame). The label images are the real ones:
// each frame goes through the mapper's own stages (depth segmentation, super-point
// association, label-TSDF integration; geometry only, 7-Scenes has no masks), and the store
// gets the per-pixel super-point labels association gave the integrator.
//   panmap-bench-frame-store [--data DIR] [--frames N] [--color] [--color-quality Q]
//                            [--compression-level L] [--voxel-size M] [--threads N] [--store DIR]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "panmap/core/error.h"
#include "panmap/core/fingerprint.h"
#include "panmap/core/progress.h"
#include "panmap/core/thread_pool.h"
#include "panmap/core/value_spread.h"
#include "panmap/io/dataset_reader.h"
#include "panmap/io/image_codec.h"
#include "panmap/io/plane_codec.h"
#include "panmap/loop/frame_store.h"
#include "panmap/map/projective_integrator.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/segmentation/panoptic_geometric.h"
#include "panmap/superpoint/superpoint_tracker.h"

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// FNV-1a over an image's pixels: load() must give back exactly what add() got, and keeping
// 200 label images in memory to compare would cost 250 MB.
template <typename Image>
uint64_t fingerprint(const Image& image) {
  panmap::Fingerprint f;
  f.add(image.data(), image.size() * sizeof(typename Image::Pixel));
  return f.value() ^ (static_cast<uint64_t>(image.width()) << 32) ^
         static_cast<uint64_t>(image.height());
}

// Times FrameStore::load of every frame of an existing store, whole and without the
// segmentation, alternating frame by frame so that both see the same page cache and host load.
void timeLoads(const std::string& folder) {
  const auto store = panmap::FrameStore::open(folder);
  const std::vector<int64_t> utimes = store->utimes();
  if (utimes.empty()) throw panmap::Error(folder + ": no frames");
  std::vector<double> whole_ms, without_ms;
  for (const int64_t utime : utimes) store->load(utime);  // into the page cache
  panmap::ProgressLine progress("loads", "frames");
  for (size_t i = 0; i < utimes.size(); ++i) {
    progress.update(i + 1, utimes.size());
    auto start = Clock::now();
    store->load(utimes[i]);
    whole_ms.push_back(msSince(start));
    start = Clock::now();
    store->load(utimes[i], panmap::FrameStore::Parts::kWithoutSegmentation);
    without_ms.push_back(msSince(start));
  }
  progress.finish();
  const panmap::ValueSpread whole = panmap::spreadOf(whole_ms);
  const panmap::ValueSpread without = panmap::spreadOf(without_ms);
  std::printf("load() of %zu frames of %s (%zu with a segmentation):\n", utimes.size(),
              folder.c_str(), store->sizeWithPanoptic());
  std::printf("  whole frame              median %6.2f  p95 %6.2f ms\n", whole.median, whole.p95);
  std::printf("  without the segmentation median %6.2f  p95 %6.2f ms\n", without.median,
              without.p95);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Store every frame of a dataset in the loop-closure frame store (depth, the per-pixel "
      "super-point labels of a geometry-only mapping run, pose, optionally colour) and print "
      "bytes per frame and add / load times."};
#ifdef PANMAP_DATA_DIR
  std::string data = std::string(PANMAP_DATA_DIR) + "/7scenes-200";
#else
  std::string data = "../shared/data/7scenes-200";
#endif
  std::string store_dir;
  int frames = 0, threads = 2;
  float voxel_size_m = panmap::TsdfMap::Config{}.voxel_size_m;
  panmap::FrameStoreConfig config;
  app.add_option("--data", data, "dataset folder (7-Scenes, ScanNet export, TUM, folder)")
      ->capture_default_str();
  app.add_option("--frames", frames, "frames to store (0 = all)");
  app.add_flag("--color", config.store_color, "store colour as JPEG too");
  app.add_option("--color-quality", config.color_quality, "JPEG quality")->capture_default_str();
  app.add_option("--compression-level", config.compression_level,
                 "zstd level of the depth and label planes (1..19)")
      ->capture_default_str();
  app.add_option("--voxel-size", voxel_size_m, "voxel size of the mapping run, metres")
      ->capture_default_str();
  app.add_option("--threads", threads, "threads of segmentation and integration")
      ->capture_default_str();
  app.add_option("--store", store_dir,
                 "store folder (must not hold a store yet; kept). Default: a temporary folder "
                 "under TMPDIR, removed at the end");
  std::string loads_of;
  app.add_option("--time-loads", loads_of,
                 "instead: time load() of every frame of the existing store DIR (for example a "
                 "labelled run's, panmap-mapper --frame-store), whole and without the "
                 "segmentation (what a re-integration reads), alternating");
  CLI11_PARSE(app, argc, argv);
  namespace fs = std::filesystem;
  if (!loads_of.empty()) {
    try {
      timeLoads(loads_of);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "panmap-bench-frame-store: error: %s\n", e.what());
      return 1;
    }
    return 0;
  }
  std::string temp_dir;
  try {
    if (store_dir.empty()) {
      std::string pattern = (fs::temp_directory_path() / "panmap-frame-store-XXXXXX").string();
      if (!::mkdtemp(pattern.data())) throw panmap::Error("cannot create a temporary folder");
      temp_dir = pattern;
      store_dir = temp_dir + "/store";
    } else if (fs::exists(store_dir + "/index.txt")) {
      throw panmap::Error(store_dir + " already holds a frame store");
    }
    config.folder = store_dir;
    config.check();

    const auto reader = panmap::openDataset(data, panmap::DatasetOptions{});
    const size_t n = frames > 0 ? std::min<size_t>(frames, reader->size()) : reader->size();
    if (n == 0) throw panmap::Error(data + ": no frames");

    // The mapper's stages that produce the per-pixel labels, with its defaults.
    panmap::ThreadPool pool(threads);
    panmap::TsdfMap::Config map_config;
    map_config.voxel_size_m = voxel_size_m;
    panmap::TsdfMap map(map_config);
    panmap::DepthSegmentationConfig segmentation_config;
    segmentation_config.num_threads = threads;
    panmap::PanopticGeometricSegmenter segmenter(segmentation_config,
                                                 panmap::SurfaceFusionConfig{});
    panmap::SuperpointTracker tracker(panmap::SuperpointConfig{});
    panmap::ProjectiveIntegrator integrator(panmap::IntegratorConfig{}, &pool);
    panmap::FrameSegmentation segmentation;
    panmap::FrameAssociation association;

    panmap::FrameStore store(config);
    std::vector<double> depth_kb, labels_kb, color_kb, total_kb, add_ms, encode_ms, load_ms,
        distinct;
    // The geometric segments a frame stored with masks keeps too (7-Scenes has none: encoded
    // here for their size, not stored).
    std::vector<double> geometric_kb, with_geometric_kb;
    std::vector<int64_t> utimes;
    std::vector<std::pair<uint64_t, uint64_t>> prints;  // depth, labels of each stored frame
    // The same images as version 1 stores kept them (PNG, zlib level 6), for comparison.
    std::vector<double> png_kb, png_encode_ms, png_decode_ms, plane_decode_ms;
    size_t no_pose = 0;
    panmap::ProgressLine progress("frame store", "frames");
    for (size_t i = 0; i < n; ++i) {
      const panmap::DatasetFrame f = reader->read(i);
      progress.update(i + 1, n);
      if (!f.T_W_C) {
        ++no_pose;
        continue;
      }
      segmenter.segment(f.rgbd, nullptr, &segmentation);
      tracker.associate(segmentation, f.rgbd, *f.T_W_C, map, &association);
      integrator.integrate(f.rgbd, *f.T_W_C, &association.pixel_labels, &map);
      const panmap::LabelImage& labels = association.pixel_labels;
      // The encoding alone (what add() costs before its file writes and fsyncs), timed on
      // the same images; a frame whose labels need the high plane encodes a little more.
      auto start = Clock::now();
      panmap::encodePlane(f.rgbd.depth, config.compression_level);
      panmap::encodePlane(labels, config.compression_level);
      if (config.store_color && !f.rgbd.color.empty()) {
        panmap::encodeJpeg(f.rgbd.color, config.color_quality);
      }
      encode_ms.push_back(msSince(start));
      start = Clock::now();
      store.add(f.rgbd, *f.T_W_C, labels);
      add_ms.push_back(msSince(start));
      const panmap::FrameStore::FrameBytes b = store.frameBytes(f.rgbd.utime);
      depth_kb.push_back(b.depth / 1000.0);
      labels_kb.push_back(b.labels / 1000.0);
      color_kb.push_back(b.color / 1000.0);
      total_kb.push_back(b.total() / 1000.0);
      geometric_kb.push_back(
          panmap::encodePlane(segmentation.geometric, config.compression_level).size() / 1000.0);
      with_geometric_kb.push_back(total_kb.back() + geometric_kb.back());
      {
        const std::vector<uint8_t> d_plane =
            panmap::encodePlane(f.rgbd.depth, config.compression_level);
        const std::vector<uint8_t> l_plane = panmap::encodePlane(labels, config.compression_level);
        auto t = Clock::now();
        panmap::decodeDepthPlane(d_plane.data(), d_plane.size(), "depth");
        panmap::decodeLabelPlane(l_plane.data(), l_plane.size(), "labels");
        plane_decode_ms.push_back(msSince(t));
        // Association's labels stay below 2^24 here: one label PNG holds them.
        t = Clock::now();
        const std::vector<uint8_t> d_png = panmap::encodeDepthPng(f.rgbd.depth, 6);
        const std::vector<uint8_t> l_png = panmap::encodeLabelPng(labels, 6);
        png_encode_ms.push_back(msSince(t));
        png_kb.push_back((d_png.size() + l_png.size()) / 1000.0);
        t = Clock::now();
        panmap::decodeDepthPng(d_png.data(), d_png.size(), "depth");
        panmap::decodeLabelPng(l_png.data(), l_png.size(), "labels");
        png_decode_ms.push_back(msSince(t));
      }
      distinct.push_back(static_cast<double>(
          std::set<int32_t>(labels.data(), labels.data() + labels.size()).size()));
      utimes.push_back(f.rgbd.utime);
      prints.emplace_back(fingerprint(f.rgbd.depth), fingerprint(labels));
    }
    progress.finish();
    if (utimes.empty()) throw panmap::Error(data + ": no frame has a pose");

    // Load every frame back (from the page cache, as a repair right after a loop closure
    // would) and check it is exactly what was stored.
    for (size_t i = 0; i < utimes.size(); ++i) {
      const auto start = Clock::now();
      const panmap::StoredFrame f = store.load(utimes[i]);
      load_ms.push_back(msSince(start));
      if (fingerprint(f.rgbd.depth) != prints[i].first ||
          fingerprint(f.labels) != prints[i].second) {
        throw panmap::Error("frame " + std::to_string(utimes[i]) +
                            " came back different from what was stored");
      }
    }
    const uint64_t bytes_on_disk = store.bytesOnDisk();
    auto start = Clock::now();
    const auto reopened = panmap::FrameStore::open(store_dir);
    const double open_ms = msSince(start);
    if (reopened->size() != utimes.size() || !reopened->problems().empty()) {
      throw panmap::Error("reopening found " + std::to_string(reopened->size()) + " of " +
                          std::to_string(utimes.size()) + " frames" +
                          (reopened->problems().empty() ? "" : ": " + reopened->problems()[0]));
    }

    std::printf(
        "frame store: %zu frames of %s%s, labels of a geometry-only run at %.0f cm, "
        "zstd level %d, colour %s\n",
        utimes.size(), data.c_str(),
        no_pose ? (" (" + std::to_string(no_pose) + " without a pose skipped)").c_str() : "",
        voxel_size_m * 100.0, config.compression_level,
        config.store_color ? ("JPEG q" + std::to_string(config.color_quality)).c_str() : "off");
    const auto row = [](const char* what, const std::vector<double>& v, const char* unit) {
      const panmap::ValueSpread s = panmap::spreadOf(v);
      std::printf("  %-18s median %7.1f  p95 %7.1f  max %7.1f %s\n", what, s.median, s.p95, s.max,
                  unit);
    };
    row("depth plane", depth_kb, "kB");
    row("label plane", labels_kb, "kB");
    if (config.store_color) row("colour JPEG", color_kb, "kB");
    row("total", total_kb, "kB");
    std::printf("  with masks a frame keeps its geometric segments too (not stored here):\n");
    row("  geometric plane", geometric_kb, "kB");
    row("  total with it", with_geometric_kb, "kB");
    row("labels per frame", distinct, "");
    std::printf("  on disk            %.1f MB (%.1f kB per frame, index included)\n",
                bytes_on_disk / 1e6, bytes_on_disk / 1e3 / utimes.size());
    row("add()", add_ms, "ms");
    row("  of it encoding", encode_ms, "ms");
    row("load()", load_ms, "ms");
    row("  decoding planes", plane_decode_ms, "ms");
    std::printf("  the same images as PNGs at zlib level 6 (store version 1):\n");
    row("  depth + labels", png_kb, "kB");
    row("  encoding", png_encode_ms, "ms");
    row("  decoding", png_decode_ms, "ms");
    std::printf("  open()             %.1f ms for %zu frames (CRC-32 of every file)\n", open_ms,
                utimes.size());
    const panmap::ValueSpread total = panmap::spreadOf(total_kb);
    std::printf("  budget 150 kB per frame: %s (max %.1f kB)\n",
                total.max <= 150.0 ? "met by every frame" : "EXCEEDED", total.max);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-bench-frame-store: error: %s\n", e.what());
    if (!temp_dir.empty()) fs::remove_all(temp_dir);
    return 1;
  }
  if (!temp_dir.empty()) fs::remove_all(temp_dir);
  return 0;
}
