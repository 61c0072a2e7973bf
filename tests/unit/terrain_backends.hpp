#pragma once
// The back-ends as types, for tests typed over them (TYPED_TEST_SUITE(..., test::Backends,
// test::BackendName)): each one's name for sb::make_terrain, the scene overrides it runs
// with, and the volume tolerance its bookkeeping meets.
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace sb::test {

// The TIN compensates retriangulation volume changes only when asked (tin.conserve_volume);
// the grids' bookkeeping is exact by construction.
struct Tin {
  static constexpr const char* kName = "tin";
  static std::vector<std::string> overrides() { return {"tin.conserve_volume=true"}; }
  static constexpr double kVolumeTolerance = 1e-12;
};
struct Grid {
  static constexpr const char* kName = "grid";
  static std::vector<std::string> overrides() { return {}; }
  static constexpr double kVolumeTolerance = 1e-12;
};
struct Sparse {
  static constexpr const char* kName = "sparse";
  static std::vector<std::string> overrides() { return {}; }
  static constexpr double kVolumeTolerance = 1e-12;
};

struct BackendName {
  template <class T>
  static std::string GetName(int) {
    return T::kName;
  }
};
using Backends = ::testing::Types<Tin, Grid, Sparse>;

}  // namespace sb::test
