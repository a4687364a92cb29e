// The file names the container targets write their entries under. The seed generator packs
// the fixtures with the same lists, so an index means the same file in both.
#pragma once

#include <string>
#include <vector>

namespace panmap {
namespace fuzz {

/// Files of every dataset layout: TUM, 7-Scenes, the ScanNet export and the generic
/// rgb/ + depth/ + intrinsics + poses layout, with two frames each so that sequences, time
/// matching and per-frame size checks are reachable; and a ScanNet .sens recording (last, so
/// the indexes of the others stay what the committed seeds were packed with).
inline const std::vector<std::string>& datasetFileNames() {
  static const std::vector<std::string> names = {
      // TUM: lists, ground truth, intrinsics and images named by time stamp.
      "rgb.txt", "depth.txt", "groundtruth.txt", "camera-intrinsics.txt", "rgb/1.000000.png",
      "depth/1.005000.png", "rgb/1.033000.png", "depth/1.040000.png",
      // 7-Scenes / tsdf-fusion.
      "frame-000000.color.png", "frame-000000.color.jpg", "frame-000000.depth.png",
      "frame-000000.pose.txt", "frame-000001.color.png", "frame-000001.depth.png",
      "frame-000001.pose.txt",
      // ScanNet SensReader export.
      "color/0.jpg", "color/0.png", "depth/0.png", "pose/0.txt", "color/1.jpg", "depth/1.png",
      "pose/1.txt", "intrinsic/intrinsic_depth.txt", "intrinsic/intrinsic_color.txt",
      "intrinsic/extrinsic_color.txt", "intrinsic/extrinsic_depth.txt", "scene0000_00.txt",
      // Generic: rgb/ + depth/ numbered images, intrinsics, TUM or 4x4 poses.
      "rgb/000000.png", "rgb/000000.jpg", "depth/000000.png", "rgb/000001.png", "depth/000001.png",
      "intrinsic.txt", "intrinsics.txt", "gt_pose.txt", "poses.txt", "pose/000000.txt",
      "pose/000001.txt",
      // ScanNet .sens recording (with scene0000_00.txt above: its metadata).
      "scene0000_00.sens"};
  return names;
}

/// Files of a COCO panoptic mask folder: the COCO file, per-frame JSONs, masks, label table.
inline const std::vector<std::string>& cocoFileNames() {
  static const std::vector<std::string> names = {"panoptic.json",
                                                 "labels.tsv",
                                                 "masks/frame-000000.color.png",
                                                 "masks/frame-000000.color.json",
                                                 "masks/0.png",
                                                 "masks/0.json"};
  return names;
}

/// Files of a ScanNet scene's ground truth.
inline const std::vector<std::string>& scannetGtFileNames() {
  static const std::vector<std::string> names = {
      "scene_vh_clean_2.ply", "scene.aggregation.json", "scene_vh_clean_2.0.010000.segs.json",
      "labels.combined.tsv", "scene_vh_clean_2.labels.ply"};
  return names;
}

}  // namespace fuzz
}  // namespace panmap
