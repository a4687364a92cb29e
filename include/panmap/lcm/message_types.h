#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace panmap {

/// What checking one encoded message found.
struct MessageCheck {
  std::string type;   ///< panmap type name ("rgbd_frame_t"), or "" when the fingerprint is unknown
  bool ok = false;    ///< decoded completely (and, when deep, its content is valid)
  int64_t utime = 0;  ///< the message's utime field when it decoded
  std::string error;  ///< why it is not ok
};

/// Identifies an encoded LCM message by its fingerprint and decodes it as that panmap type.
/// @param deep also decode embedded images and check sizes and values (rgbd, pose, panoptic)
MessageCheck checkMessage(const void* data, size_t size, bool deep);

/// Names of every panmap message type.
std::vector<std::string> messageTypeNames();

}  // namespace panmap
