#pragma once

#include <cstdint>
#include <vector>

#include "panmap/mapper/objects.h"
#include "panmap/object_list_t.hpp"

namespace panmap {

/// PANMAP_OBJECTS message of the mapped objects at map time `utime` (exact: doubles travel as
/// doubles, the confidence as the float it is).
object_list_t toMessage(const std::vector<MappedObject>& objects, int64_t utime);

/// Objects of a PANMAP_OBJECTS message. Throws Error naming the object when an array length
/// disagrees with its count, an id is not positive, or the orientation is not a finite
/// quaternion.
std::vector<MappedObject> fromMessage(const object_list_t& msg);

}  // namespace panmap
