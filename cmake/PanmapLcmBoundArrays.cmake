# cmake -DDIR=<folder of lcm-gen C++ headers> -P PanmapLcmBoundArrays.cmake
#
# lcm-gen's C++ decoders resize every variable-length array from its length field before
# reading the elements, so a 30-byte message claiming 2^31 elements allocates (and zero-fills)
# gigabytes before the decoder notices the message is short (found by fuzz/fuzz_lcm_messages).
# Every element takes at least one byte on the wire, so a length above the bytes left cannot
# be valid: this inserts that check before each resize, making such messages fail like any
# other truncated one (decode returns -1). String lengths count the terminating NUL, so one
# below 1 is refused too (the decoders compute length - 1, which overflows for INT32_MIN).
cmake_minimum_required(VERSION 3.16)
file(GLOB headers ${DIR}/*.hpp)
set(pattern "([ \t]*)this->([A-Za-z0-9_]+)\\.resize\\(this->([A-Za-z0-9_]+)\\);")
set(guard "\\1if (this->\\3 < 0 || this->\\3 > maxlen - pos) return -1;\n")
foreach(header ${headers})
  file(READ ${header} text)
  string(FIND "${text}" "panmap: array lengths bounded" done)
  if(NOT done EQUAL -1)
    continue()
  endif()
  string(REGEX MATCHALL "\\.resize\\(" all "${text}")
  string(REGEX MATCHALL "this->[A-Za-z0-9_]+\\.resize\\(this->[A-Za-z0-9_]+\\)" known "${text}")
  list(LENGTH all n_all)
  list(LENGTH known n_known)
  if(NOT n_all EQUAL n_known)
    message(FATAL_ERROR "${header}: a resize() of a form PanmapLcmBoundArrays.cmake does not know")
  endif()
  string(REGEX REPLACE "${pattern}" "${guard}\\1this->\\2.resize(this->\\3);" text "${text}")
  string(REGEX REPLACE "if\\((__[A-Za-z0-9_]+) > maxlen - pos\\) return -1;"
         "if (\\1 < 1 || \\1 > maxlen - pos) return -1;" text "${text}")
  file(WRITE ${header} "// panmap: array lengths bounded by the bytes left (cmake/PanmapLcmBoundArrays.cmake)\n${text}")
endforeach()
