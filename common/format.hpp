#pragma once
// Numbers written into text files (scene overrides, sessions, exports): the shortest text
// that reads back as the same double ("0.0025", not "0.0025000000000000001"), locale-free.
// O(1).
#include <charconv>
#include <string>

namespace sb {

inline std::string exact_number(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace sb
