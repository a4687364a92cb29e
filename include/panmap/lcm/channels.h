#pragma once

namespace panmap {

// Default LCM channel names (DESIGN 5); every process lets the user override them.
constexpr const char* kChannelRgbd = "CAMERA_RGBD";
constexpr const char* kChannelPose = "CAMERA_POSE";
constexpr const char* kChannelPanoptic = "PANOPTIC";
constexpr const char* kChannelStatus = "PANMAP_STATUS";
constexpr const char* kChannelObjects = "PANMAP_OBJECTS";
constexpr const char* kChannelOctomap = "PANMAP_OCTOMAP";
constexpr const char* kChannelGraph = "PANMAP_GRAPH";
constexpr const char* kChannelLabels = "PANMAP_LABELS";
constexpr const char* kChannelCommand = "PANMAP_COMMAND";
constexpr const char* kChannelPoseCorrection = "PANMAP_POSE_CORRECTION";

}  // namespace panmap
