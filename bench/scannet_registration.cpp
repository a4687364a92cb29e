// Measures how well each ScanNet colour registration lines colour edges up with depth edges:
// the mean colour-gradient magnitude at depth discontinuities (higher = better aligned).
//   panmap-bench-registration [SCANNET_EXPORT_DIR]
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "panmap/io/dataset_reader.h"
#include "panmap/io/opencv_image.h"

namespace {

double edgeAlignment(const panmap::ColorImage& color, const panmap::DepthImage& depth) {
  cv::Mat gray, gx, gy;
  cv::cvtColor(panmap::asMat(color), gray, cv::COLOR_RGB2GRAY);
  cv::Sobel(gray, gx, CV_32F, 1, 0);
  cv::Sobel(gray, gy, CV_32F, 0, 1);
  double sum = 0.0;
  int n = 0;
  for (int v = 2; v < depth.height() - 2; ++v) {
    for (int u = 2; u < depth.width() - 2; ++u) {
      const int z = depth(u, v), zr = depth(u + 1, v), zd = depth(u, v + 1);
      if (!z || !zr || !zd) continue;
      if (std::abs(z - zr) > 80 || std::abs(z - zd) > 80) {  // > 8 cm step: a depth edge
        sum += std::hypot(gx.at<float>(v, u), gy.at<float>(v, u));
        ++n;
      }
    }
  }
  return n ? sum / n : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string dir = argc > 1 ? argv[1] : "../shared/data/scannet-export-3";
  try {
    for (auto mode : {panmap::ColorRegistration::kResize, panmap::ColorRegistration::kReproject}) {
      panmap::DatasetOptions options;
      options.layout = panmap::DatasetLayout::kScanNet;
      options.registration = mode;
      const auto reader = panmap::openDataset(dir, options);
      double total = 0.0;
      for (size_t i = 0; i < reader->size(); ++i) {
        const panmap::DatasetFrame f = reader->read(i);
        total += edgeAlignment(f.rgbd.color, f.rgbd.depth);
      }
      std::printf("%-10s mean colour gradient at depth edges over %zu frames: %.2f\n",
                  mode == panmap::ColorRegistration::kResize ? "resize" : "reproject",
                  reader->size(), total / reader->size());
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-bench-registration: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
