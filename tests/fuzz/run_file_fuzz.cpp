// libFuzzer target: the run-file reader. The input does not fuzz HDF5's own parser (a
// third-party library): it describes the contents of a well-formed HDF5 file -- for each
// dataset the reader uses, whether it exists, its rank, shape (small, or declared huge without
// data), type and values, and the rasters' origin_m and spacing_m -- which is written with the
// HDF5 API and read back with read_run_file. It must then hold rasters of at least 2 x 2
// finite values on one lattice, finite vertices and indices that name them, or raise
// InputError; nothing else.
#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "common/input_error.hpp"
#include "harness/io/run_file.hpp"

namespace {

// Reads the fuzz input as a stream of small decisions; zeros when it runs out.
class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  double number() {
    static const double special[] = {0.0,
                                     0.05,
                                     0.1,
                                     -1.0,
                                     1e308,
                                     -1e300,
                                     1e-300,
                                     2.5e-3,
                                     1e10,
                                     -1e10,
                                     5e-324,
                                     1e9,
                                     0.5,
                                     1.0,
                                     -0.0,
                                     3.0,
                                     std::numeric_limits<double>::infinity(),
                                     std::numeric_limits<double>::quiet_NaN()};
    const std::uint8_t b = byte();
    if (b < 2 * std::size(special)) return special[b % std::size(special)];
    return (static_cast<double>(b) - 160.0) * 0.01;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

void write_dataset(hid_t file, const std::string& name, std::size_t columns, Bytes& in) {
  const std::uint8_t how = in.byte();
  if (how == 255) return;  // absent
  const int rank = how % 7 == 0 ? 1 : how % 11 == 0 ? 3 : 2;
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  const bool huge = how % 13 == 5;
  for (int i = 0; i < rank; ++i) dims[static_cast<std::size_t>(i)] = huge ? 30000 : in.byte() % 5;
  if (rank == 2 && in.byte() % 4 != 0) dims[1] = columns;
  static const hid_t types[] = {H5T_NATIVE_DOUBLE, H5T_NATIVE_FLOAT, H5T_NATIVE_INT64, H5T_NATIVE_UINT32,
                                H5T_NATIVE_INT8};
  const hid_t type = types[in.byte() % std::size(types)];
  const hid_t space = H5Screate_simple(rank, dims.data(), nullptr);
  const hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
  if (huge) {
    std::vector<hsize_t> chunk(dims.size(), 1);
    chunk.back() = 1024;
    H5Pset_chunk(plist, rank, chunk.data());
  }
  const hid_t set = H5Dcreate2(file, name.c_str(), type, space, H5P_DEFAULT, plist, H5P_DEFAULT);
  std::size_t count = 1;
  for (hsize_t d : dims) count *= d;
  if (set >= 0 && !huge && count > 0) {
    std::vector<double> values(count);
    for (double& v : values) v = in.number();
    H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  }
  if (set >= 0 && name.find("raster") != std::string::npos) {
    for (const char* attr : {"origin_m", "spacing_m"}) {
      const hsize_t n = in.byte() % 3 + 1;
      const hid_t aspace = H5Screate_simple(1, &n, nullptr);
      const hid_t a = H5Acreate2(set, attr, H5T_NATIVE_DOUBLE, aspace, H5P_DEFAULT, H5P_DEFAULT);
      std::vector<double> v(n);
      for (double& x : v) x = in.number();
      if (a >= 0) {
        H5Awrite(a, H5T_NATIVE_DOUBLE, v.data());
        H5Aclose(a);
      }
      H5Sclose(aspace);
    }
  }
  if (set >= 0) H5Dclose(set);
  H5Pclose(plist);
  H5Sclose(space);
}

void string_attribute(hid_t obj, const char* name, const char* value) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, std::strlen(value) + 1);
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t a = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(a, type, value);
  H5Aclose(a);
  H5Sclose(space);
  H5Tclose(type);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  Bytes in(data, size);
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("sb_run_file_fuzz_" + std::to_string(::getpid()) + ".h5");
  {
    const hid_t file = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0) return 0;
    string_attribute(file, "backend", "grid");
    string_attribute(file, "summary", in.byte() % 8 == 1 ? "[1]" : "{}");
    for (const char* g : {"/steps", "/initial", "/final", "/final/mesh"}) {
      const hid_t group = H5Gcreate2(file, g, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
      if (group >= 0) H5Gclose(group);
    }
    write_dataset(file, "/steps/stamp", 1, in);
    write_dataset(file, "/steps/volume_m3", 1, in);
    write_dataset(file, "/initial/raster", 0, in);
    write_dataset(file, "/final/raster", 0, in);
    write_dataset(file, "/final/mesh/vertices", 3, in);
    write_dataset(file, "/final/mesh/triangles", 3, in);
    write_dataset(file, "/final/mesh/constrained_edges", 2, in);
    H5Fclose(file);
  }
  try {
    const sb::RunFile r = sb::read_run_file(path);
    for (const sb::Raster* raster : {&r.initial_raster, &r.final_raster}) {
      if (raster->nx < 2 || raster->ny < 2 || raster->values.size() != raster->nx * raster->ny) __builtin_trap();
      for (double v : raster->values)
        if (!std::isfinite(v)) __builtin_trap();
      if (!(raster->spacing_m > 0.0)) __builtin_trap();
    }
    if (r.initial_raster.nx != r.final_raster.nx || r.initial_raster.ny != r.final_raster.ny) __builtin_trap();
    for (const auto& v : r.mesh.vertices)
      if (!v.allFinite()) __builtin_trap();
    for (const auto& t : r.mesh.triangles)
      for (std::uint32_t i : t)
        if (i >= r.mesh.vertices.size()) __builtin_trap();
    for (const auto& e : r.mesh.constrained_edges)
      for (std::uint32_t i : e)
        if (i >= r.mesh.vertices.size()) __builtin_trap();
  } catch (const sb::InputError&) {
  }
  std::filesystem::remove(path);
  return 0;
}
