#include "panmap/core/byte_sink.h"

#include <cstring>

#include "panmap/core/error.h"

namespace panmap {

void VectorSink::append(const uint8_t* data, size_t size) {
  out_->insert(out_->end(), data, data + size);
}

void VectorSink::overwrite(uint64_t offset, const uint8_t* data, size_t size) {
  if (offset > out_->size() || size > out_->size() - offset) {
    throw Error("VectorSink::overwrite past the end");
  }
  std::memcpy(out_->data() + offset, data, size);
}

}  // namespace panmap
