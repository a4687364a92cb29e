// panmap-optimizer: the final optimisation as an LCM process. Subscribes PANMAP_GRAPH,
// publishes PANMAP_LABELS (same request_id), and keeps running for the next request.
#include <csignal>
#include <cstdio>

#include <CLI/CLI.hpp>

#include "panmap/core/error.h"
#include "panmap/core/memory_policy.h"
#include "panmap/lcm/optimizer_node.h"
#include "panmap/mapper/config_file.h"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "panmap's optimiser process: answers each super-point graph (PANMAP_GRAPH) with "
      "optimised semantic and instance labels (PANMAP_LABELS). Runs until SIGINT/SIGTERM."};
  std::string url;
  panmap::OptimizerNode::Config config;
  bool no_regularise = false, no_refine = false;
  std::string config_path;
  app.add_option("--lcm-url", url, "LCM URL (default: LCM's default, LCM_DEFAULT_URL)");
  app.add_option("--config", config_path,
                 "YAML config; its optimiser section is used (see panmap-mapper --print-config)");
  app.add_option("--channel-graph", config.channel_graph)->capture_default_str();
  app.add_option("--channel-labels", config.channel_labels)->capture_default_str();
  app.add_flag("--no-regularise", no_regularise, "skip the semantic regularisation (III-C)");
  app.add_flag("--no-refine", no_refine, "skip the instance refinement (III-D)");
  CLI11_PARSE(app, argc, argv);
  panmap::applyMemoryPolicy(argv);
  try {
    if (!config_path.empty()) config.optimiser = panmap::loadConfig(config_path).optimiser;
    if (no_regularise) config.optimiser.regularise = false;
    if (no_refine) config.optimiser.refine = false;
    // An empty channel, or answers on the channel it listens to, waited forever in silence.
    if (config.channel_graph.empty() || config.channel_labels.empty()) {
      throw panmap::Error("--channel-graph and --channel-labels must name channels");
    }
    if (config.channel_graph == config.channel_labels) {
      throw panmap::Error("--channel-graph and --channel-labels are both " + config.channel_graph +
                          ": the answers would come back as graphs");
    }
    lcm::LCM lcm(url);
    if (!lcm.good()) {
      std::fprintf(stderr, "panmap-optimizer: error: cannot open LCM URL '%s'\n", url.c_str());
      return 1;
    }
    panmap::OptimizerNode node(&lcm, config);
    std::signal(SIGINT, onSignal);
    std::signal(SIGTERM, onSignal);
    std::fprintf(stderr, "panmap-optimizer: waiting for graphs on %s\n",
                 config.channel_graph.c_str());
    while (!g_stop) lcm.handleTimeout(200);
    std::fprintf(stderr, "panmap-optimizer: answered %lld graphs\n",
                 static_cast<long long>(node.answered()));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-optimizer: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
