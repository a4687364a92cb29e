#pragma once

#include <string>

#include "panmap/graph/optimiser.h"
#include "panmap/mapper/mapper.h"

namespace panmap {

/// Every tunable of a mapping run: the per-frame pipeline and the final optimisation.
struct PanmapConfig {
  MapperConfig mapper;
  OptimiserConfig optimiser;
};

/// Reads a YAML config (OpenCV FileStorage dialect, `%YAML:1.0` header): sections map,
/// integrator, depth_segmentation, fusion, superpoints, graph, optimiser, each optional, each
/// key optional (missing keys keep their defaults). Unknown sections or keys, wrong types and
/// values that fail a component's check() throw Error naming the file and the key.
PanmapConfig loadConfig(const std::string& path);

/// The YAML text of a config, every key present with a comment (what --print-config shows).
std::string configToYaml(const PanmapConfig& config);

}  // namespace panmap
