#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "panmap/io/image_codec.h"
#include "panmap/io/scannet_sens.h"
#include "panmap/io/text_files.h"
#include "test_helpers.h"

namespace panmap {
namespace test {

/// Writes the shared ScanNet export fixture (../shared/data/scannet-export-3) as the .sens
/// recording it was exported from would be, at `sens_path`: its JPEGs as they are, its depth
/// deflated, its poses and intrinsics as floats; and links the scene metadata beside it, as
/// ScanNet's download script leaves a scan's folder.
inline void writeScanNetExportAsSens(const std::string& sens_path) {
  namespace fs = std::filesystem;
  const std::string src = dataDir("scannet-export-3");
  ScanNetSensHeader h;
  h.sensor_name = "StructureSensor";
  h.intrinsic_color = readMatrixFile(src + "/intrinsic/intrinsic_color.txt", 4, 4).cast<float>();
  h.intrinsic_depth = readMatrixFile(src + "/intrinsic/intrinsic_depth.txt", 4, 4).cast<float>();
  h.color_width = 1296;
  h.color_height = 968;
  h.depth_width = 640;
  h.depth_height = 480;
  std::vector<ScanNetSensFrame> frames(3);
  for (int i = 0; i < 3; ++i) {
    const std::string n = std::to_string(i);
    frames[i].color = readFileBytes(src + "/color/" + n + ".jpg");
    frames[i].depth = compressSensDepth(readDepthFile(src + "/depth/" + n + ".png"));
    frames[i].camera_to_world = readMatrixFile(src + "/pose/" + n + ".txt", 4, 4).cast<float>();
  }
  writeScanNetSens(sens_path, h, frames);
  fs::create_symlink(src + "/scene0707_00.txt",
                     (fs::path(sens_path).parent_path() / "scene0707_00.txt").string());
}

}  // namespace test
}  // namespace panmap
