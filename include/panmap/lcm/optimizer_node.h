#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "panmap/graph/optimiser.h"
#include "panmap/graph_labels_t.hpp"

namespace panmap {

/// The panmap-optimizer process's logic: answers every PANMAP_GRAPH message with a
/// PANMAP_LABELS message carrying the same request_id. Never throws out of the LCM handler:
/// malformed graphs are counted by reason and answered with nothing.
class OptimizerNode {
 public:
  /// Channels and solver settings.
  struct Config {
    std::string channel_graph = "PANMAP_GRAPH";
    std::string channel_labels = "PANMAP_LABELS";
    OptimiserConfig optimiser;
  };

  /// Subscribes on `lcm` (not owned; it must outlive the node).
  OptimizerNode(lcm::LCM* lcm, const Config& config);

  /// Graphs solved and answered so far.
  int64_t answered() const { return answered_; }
  /// Copies of the last graph answered again from the cache, without solving.
  int64_t repeated() const { return repeated_; }
  /// Messages refused, by reason.
  const std::map<std::string, int64_t>& rejected() const { return rejected_; }

 private:
  void onGraph(const lcm::ReceiveBuffer* buffer, const std::string& channel);

  lcm::LCM* lcm_;
  Config config_;
  int64_t answered_ = 0;
  int64_t repeated_ = 0;
  std::optional<graph_labels_t> last_answer_;
  size_t last_key_ = 0;
  std::map<std::string, int64_t> rejected_;
};

}  // namespace panmap
