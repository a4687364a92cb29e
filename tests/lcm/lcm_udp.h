// Helpers of the end-to-end tests that talk LCM over loopback UDP multicast.
#pragma once

#include <cstdint>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "panmap/status_t.hpp"

namespace panmap {
namespace test {

/// Counts PANMAP_STATUS messages and keeps the last state.
struct StatusWatch {
  int received = 0;
  std::string state;
  void onStatus(const lcm::ReceiveBuffer*, const std::string&, const status_t* msg) {
    ++received;
    state = msg->state;
  }
};

/// True when a message published on this URL comes back to a subscriber of the same process
/// (multicast on loopback is configured, see scripts/setup.sh).
inline bool multicastWorks(const std::string& url) {
  lcm::LCM lcm(url);
  if (!lcm.good()) return false;
  int received = 0;
  auto* sub = lcm.subscribeFunction(
      "PANMAP_PROBE", +[](const lcm::ReceiveBuffer*, const std::string&, int* n) { ++*n; },
      &received);
  const uint8_t probe[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  for (int attempt = 0; attempt < 3 && received == 0; ++attempt) {
    lcm.publish("PANMAP_PROBE", probe, sizeof(probe));
    lcm.handleTimeout(300);
  }
  lcm.unsubscribe(sub);
  return received > 0;
}

/// Why an end-to-end test skips where multicast is unavailable.
constexpr const char* kNoMulticast =
    "UDP multicast on loopback is unavailable here (run scripts/setup.sh as root: ip link set lo "
    "multicast on; ip route add 239.255.76.0/24 dev lo)";

}  // namespace test
}  // namespace panmap
