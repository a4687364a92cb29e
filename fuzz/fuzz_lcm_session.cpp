// Feeds a stream of LCM messages on the input channels (a container: per entry the channel
// and the body) to a MappingSession over a fresh Mapper, then flushes it.
#include <cstddef>
#include <cstdint>
#include <exception>
#include <memory>
#include <vector>

#include "fuzz_common.h"
#include "lcm_fingerprint.h"
#include "panmap/lcm/channels.h"
#include "panmap/lcm/conversions.h"
#include "panmap/lcm/mapping_session.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Every input starts from an empty map. Building a Mapper costs more than most runs (the
  // occupancy tree allocates its ray buffers), so one is kept while no frame reaches it: only
  // integrate() changes a mapper. One thread keeps runs reproducible.
  static std::unique_ptr<panmap::Mapper> mapper;
  static bool mapper_touched = true;
  if (mapper_touched) {
    panmap::MapperConfig config;
    config.num_threads = 1;
    // Coarse voxels and occupancy cells: the same code paths at a fraction of the cost (the
    // target is after input handling, not mapping throughput).
    config.map.voxel_size_m = 0.05f;
    config.occupancy.resolution_m = 0.2;
    mapper = std::make_unique<panmap::Mapper>(config);
  }
  panmap::MappingSession session(panmap::SessionOptions{}, mapper.get());
  for (const panmap::fuzz::Entry& e : panmap::fuzz::unpack(data, size)) {
    // Entry name: bits 0-1 the channel (the fourth is one the session ignores); bit 7 sends
    // the bytes as they are, without the channel type's fingerprint (wrong or no type).
    const int channel = e.name & 3;
    const bool raw = (e.name & 0x80) != 0;
    const uint8_t* body = e.bytes.data();
    const size_t n = e.bytes.size();
    std::vector<uint8_t> bytes;
    const char* name = panmap::kChannelStatus;
    switch (channel) {
      case 0:
        name = panmap::kChannelRgbd;
        bytes = raw ? e.bytes : panmap::fuzz::withFingerprint<panmap::rgbd_frame_t>(body, n);
        break;
      case 1:
        name = panmap::kChannelPose;
        bytes = raw ? e.bytes : panmap::fuzz::withFingerprint<panmap::pose_t>(body, n);
        break;
      case 2:
        name = panmap::kChannelPanoptic;
        bytes = raw ? e.bytes : panmap::fuzz::withFingerprint<panmap::panoptic_t>(body, n);
        break;
      default:
        bytes = e.bytes;
        break;
    }
    // MappingSession counts bad input and never throws (the live process relies on it), so
    // no try/catch here: an exception escaping is a finding.
    session.handle(name, bytes.data(), bytes.size());
  }
  session.flush();
  // A frame handed to the mapper may have changed it even when integrate() refused it late;
  // the synchroniser's own refusals never reach it.
  const panmap::SessionStats stats = session.stats();
  mapper_touched = stats.frames_integrated > 0;
  for (const auto& [reason, n] : stats.rejected) {
    if (reason.rfind("frame: ", 0) == 0 && reason != "frame: no pose" &&
        reason != "frame: synchroniser queue full") {
      mapper_touched = true;
    }
  }
  return 0;
}
