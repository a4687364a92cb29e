#pragma once

#include <string>

#include "panmap/graph/optimiser.h"
#include "panmap/mapper/frame_sync.h"
#include "panmap/mapper/mapper.h"

namespace panmap {

/// Every tunable of a mapping run: the per-frame pipeline, the final optimisation, and how
/// the processes match frames, poses and masks as they stream in (not part of a map: a loaded
/// map takes whatever the config says).
struct PanmapConfig {
  MapperConfig mapper;
  OptimiserConfig optimiser;
  SyncConfig sync;
};

/// A component's check message with the component's field names put as the config's keys
/// ("OptimiserConfig.objects.min_area_m2 ..." -> "objects.min_area_m2 ..."); others unchanged.
std::string asConfigKeys(const std::string& message);

/// Reads a YAML config (OpenCV FileStorage dialect, `%YAML:1.0` header): sections map,
/// integrator, depth_segmentation, fusion, superpoints, graph, optimiser, sync, each optional, each
/// key optional (missing keys keep their defaults). Unknown sections or keys, wrong types and
/// values that fail a component's check() throw Error naming the file and the key.
PanmapConfig loadConfig(const std::string& path);

/// loadConfig(path) with the keys the file leaves out taken from `base` instead of the
/// defaults (a loaded map's settings, which a config may only restate). Throws as loadConfig.
PanmapConfig loadConfig(const std::string& path, const PanmapConfig& base);

/// One setting that differs between two configs, by its YAML name and printed values.
struct SettingDifference {
  std::string key;     ///< "section.key" as --print-config shows it; empty: none differs
  std::string have;    ///< the value in the first config ("none": no depth calibration)
  std::string wanted;  ///< the value in the second
};

/// The first mapping setting that differs between `have` and `wanted`; key empty when every
/// one agrees. Optimiser settings are not compared.
SettingDifference mapperSettingDifference(const MapperConfig& have, const MapperConfig& wanted);

/// The YAML text of a config, every key present with a comment (what --print-config shows).
std::string configToYaml(const PanmapConfig& config);

}  // namespace panmap
