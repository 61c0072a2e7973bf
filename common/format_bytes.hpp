#pragma once
// Byte counts for people: "123 B", "45.6 KiB", "7.89 MiB", "2.50 GiB" (powers of 1024). O(1).
// (harness/render/colour.hpp declares the same function for the pictures' labels.)
#include <string>

namespace sb {

std::string format_bytes(double bytes);

}  // namespace sb
