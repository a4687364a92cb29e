#include "panmap/lcm/optimizer_node.h"

#include <chrono>
#include <cstdio>
#include <functional>
#include <string_view>

#include "panmap/core/error.h"
#include "panmap/lcm/decode.h"
#include "panmap/lcm/graph_conversions.h"

namespace panmap {

OptimizerNode::OptimizerNode(lcm::LCM* lcm, const Config& config) : lcm_(lcm), config_(config) {
  config_.optimiser.check();
  lcm_->subscribe(config_.channel_graph, &OptimizerNode::onGraph, this);
}

void OptimizerNode::onGraph(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
  // Called from LCM's C code: nothing may escape.
  try {
    superpoint_graph_t msg;
    if (!decodeExactly(buffer->data, buffer->data_size, &msg)) {
      ++rejected_["malformed " + channel];
      std::fprintf(stderr, "panmap-optimizer: malformed message on %s ignored\n", channel.c_str());
      return;
    }
    // A mapper publishes its final graph again until answered: a copy of the graph just
    // solved gets the same answer without solving again.
    const std::string_view bytes(static_cast<const char*>(buffer->data), buffer->data_size);
    const size_t key = std::hash<std::string_view>{}(bytes);
    if (last_answer_ && key == last_key_ && msg.request_id == last_answer_->request_id) {
      lcm_->publish(config_.channel_labels, &*last_answer_);
      ++repeated_;
      return;
    }
    const auto start = std::chrono::steady_clock::now();
    GraphLabels labels = optimise(fromMessage(msg), config_.optimiser);
    labels.solve_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const int64_t now = std::chrono::duration_cast<std::chrono::microseconds>(
                            std::chrono::system_clock::now().time_since_epoch())
                            .count();
    const graph_labels_t out = toMessage(labels, now, msg.request_id);
    lcm_->publish(config_.channel_labels, &out);
    ++answered_;
    last_answer_ = out;
    last_key_ = key;
  } catch (const std::exception& e) {
    ++rejected_["bad graph"];
    std::fprintf(stderr, "panmap-optimizer: graph refused: %s\n", e.what());
  }
}

}  // namespace panmap
