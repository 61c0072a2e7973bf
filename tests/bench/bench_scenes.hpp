#pragma once
// Scenes shared by the benchmarks.

namespace sb::bench {

// Dunes over the paper's domain (a square whose diagonal is 1 m), a 2 cm disk tool at the
// centre: the terrain of the haptics and TIN query benchmarks.
inline constexpr const char* kPaperDunesScene = R"(
[domain]
size_m = [0.70710678, 0.70710678]
[terrain]
kind = "dunes"
height_m = 0.1
amplitude_m = 0.02
wavelength_m = 0.2
[tool]
shape = "disk"
radius_m = 0.02
[stroke]
path_m = [[0.35, 0.35]]
)";

}  // namespace sb::bench
