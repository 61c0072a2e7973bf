#include "harness/io/run_file.hpp"

#include <hdf5.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <optional>
#include <span>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/format_bytes.hpp"
#include "common/input_error.hpp"
#include "harness/run/preflight.hpp"
#include "sandbench/version.hpp"

namespace sb {

namespace {

// Owns one HDF5 identifier and closes it with the matching function.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t), const std::string& what) : id_(id), close_(close) {
    if (id_ < 0) throw std::runtime_error("HDF5: cannot " + what);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept : id_(other.id_), close_(other.close_) { other.id_ = -1; }
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  operator hid_t() const { return id_; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void check(herr_t status, const std::string& what) {
  if (status < 0) throw std::runtime_error("HDF5: cannot " + what);
}

Handle group(hid_t parent, const std::string& name) {
  return Handle(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                "create group " + name);
}

// Strings are variable-length UTF-8: any size (a fixed-length attribute is limited to 64 KiB)
// and read by h5py as str.
hid_t vl_string_type() {
  const hid_t type = H5Tcopy(H5T_C_S1);
  if (type >= 0 && (H5Tset_size(type, H5T_VARIABLE) < 0 || H5Tset_cset(type, H5T_CSET_UTF8) < 0)) {
    H5Tclose(type);
    return -1;
  }
  return type;
}

void string_attribute(hid_t obj, const std::string& name, const std::string& value) {
  Handle type(vl_string_type(), H5Tclose, "make a string type");
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "create scalar space");
  Handle attr(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              "create attribute " + name);
  const char* data = value.c_str();
  check(H5Awrite(attr, type, &data), "write attribute " + name);
}

void string_dataset(hid_t parent, const std::string& name, const std::string& value) {
  Handle type(vl_string_type(), H5Tclose, "make a string type");
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "create scalar space");
  Handle set(H5Dcreate2(parent, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose,
             "create dataset " + name);
  const char* data = value.c_str();
  check(H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, &data), "write " + name);
}

// Integers and booleans keep their type: int64 and uint8 (0 or 1).
void integer_attribute(hid_t obj, const std::string& name, hid_t file_type, hid_t mem_type, const void* value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "create scalar space");
  Handle attr(H5Acreate2(obj, name.c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              "create attribute " + name);
  check(H5Awrite(attr, mem_type, value), "write attribute " + name);
}

void double_attribute(hid_t obj, const std::string& name, const std::vector<double>& values) {
  const hsize_t n = values.size();
  Handle space(n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose, "create space");
  Handle attr(H5Acreate2(obj, name.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              "create attribute " + name);
  check(H5Awrite(attr, H5T_NATIVE_DOUBLE, values.data()), "write attribute " + name);
}

// Creates a dataset of the given shape (file type: the memory type unless given), chunked and
// compressed when large.
Handle create_dataset(hid_t parent, const std::string& name, hid_t mem_type, const std::vector<hsize_t>& dims,
                      hid_t file_type = -1) {
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, "create space");
  Handle plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "create property list");
  std::size_t count = 1;
  for (hsize_t d : dims) count *= d;
  if (count > 4096) {  // chunk and compress large arrays
    std::vector<hsize_t> chunk = dims;
    chunk[0] = std::min<hsize_t>(dims[0], std::max<hsize_t>(1, 65536 / std::max<hsize_t>(1, count / dims[0])));
    check(H5Pset_chunk(plist, static_cast<int>(chunk.size()), chunk.data()), "chunk " + name);
    // Byte shuffling first: the coordinates' high bytes repeat, and deflate then finds them.
    check(H5Pset_shuffle(plist), "shuffle " + name);
    check(H5Pset_deflate(plist, 4), "compress " + name);
  }
  return Handle(
      H5Dcreate2(parent, name.c_str(), file_type < 0 ? mem_type : file_type, space, H5P_DEFAULT, plist, H5P_DEFAULT),
      H5Dclose, "create dataset " + name);
}

template <typename T>
void dataset(hid_t parent, const std::string& name, hid_t mem_type, const T* data, std::vector<hsize_t> dims,
             hid_t file_type = -1) {
  Handle set = create_dataset(parent, name, mem_type, dims, file_type);
  std::size_t count = 1;
  for (hsize_t d : dims) count *= d;
  if (count > 0) check(H5Dwrite(set, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "write " + name);
}

// Writes rows [first, first + rows) of a 2-D dataset of `columns` columns.
void write_rows(hid_t set, hid_t mem_type, const void* data, hsize_t first, hsize_t rows, hsize_t columns,
                const std::string& name) {
  if (rows == 0) return;
  Handle file_space(H5Dget_space(set), H5Sclose, "space of " + name);
  const hsize_t start[2] = {first, 0}, count[2] = {rows, columns};
  check(H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, count, nullptr), "select rows of " + name);
  Handle mem_space(H5Screate_simple(2, count, nullptr), H5Sclose, "create space");
  check(H5Dwrite(set, mem_type, mem_space, file_space, H5P_DEFAULT, data), "write " + name);
}

// The final mesh, written as the terrain hands it over: no copy of the whole mesh is held.
class MeshWriter final : public MeshSink {
 public:
  explicit MeshWriter(hid_t group) : group_(group) {}
  void begin(std::size_t vertices, std::size_t triangles, std::size_t edges) override {
    vertices_.emplace(create_dataset(group_, "vertices", H5T_NATIVE_DOUBLE, {vertices, 3}));
    triangles_.emplace(create_dataset(group_, "triangles", H5T_NATIVE_UINT32, {triangles, 3}));
    edges_.emplace(create_dataset(group_, "constrained_edges", H5T_NATIVE_UINT32, {edges, 2}));
  }
  void vertices(std::span<const Vec3> v) override {
    // Vec3 is three packed doubles.
    static_assert(sizeof(Vec3) == 3 * sizeof(double));
    write_rows(*vertices_, H5T_NATIVE_DOUBLE, v.data(), vertices_done_, v.size(), 3, "vertices");
    vertices_done_ += v.size();
  }
  void triangles(std::span<const std::array<std::uint32_t, 3>> t) override {
    write_rows(*triangles_, H5T_NATIVE_UINT32, t.data(), triangles_done_, t.size(), 3, "triangles");
    triangles_done_ += t.size();
  }
  void constrained_edges(std::span<const std::array<std::uint32_t, 2>> e) override {
    write_rows(*edges_, H5T_NATIVE_UINT32, e.data(), edges_done_, e.size(), 2, "constrained_edges");
    edges_done_ += e.size();
  }

 private:
  hid_t group_;
  std::optional<Handle> vertices_, triangles_, edges_;
  hsize_t vertices_done_ = 0, triangles_done_ = 0, edges_done_ = 0;
};

void raster_dataset(hid_t parent, const std::string& name, const Raster& r) {
  dataset(parent, name, H5T_NATIVE_DOUBLE, r.values.data(), {r.ny, r.nx});
  Handle set(H5Dopen2(parent, name.c_str(), H5P_DEFAULT), H5Dclose, "open " + name);
  double_attribute(set, "origin_m", {r.origin_m.x(), r.origin_m.y()});
  double_attribute(set, "spacing_m", {r.spacing_m});
}

std::string utc_now() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

// Step fields by name, in the order they are written: real ones (double) ...
template <typename Fn>
void for_each_real_step_field(bool energy, Fn&& fn) {
  fn("time_tool_s", [](const StepRecord& r) { return r.time_tool_s; });
  fn("time_erosion_s", [](const StepRecord& r) { return r.time_erosion_s; });
  fn("time_simplify_s", [](const StepRecord& r) { return r.time_simplify_s; });
  fn("time_detect_s", [](const StepRecord& r) { return r.time_detect_s; });
  fn("time_remove_s", [](const StepRecord& r) { return r.time_remove_s; });
  fn("time_total_s", [](const StepRecord& r) { return r.total_s(); });
  fn("volume_m3", [](const StepRecord& r) { return r.volume_m3; });
  fn("volume_delta_tool", [](const StepRecord& r) { return r.volume_delta_tool; });
  fn("volume_delta_erosion", [](const StepRecord& r) { return r.volume_delta_erosion; });
  fn("volume_delta_simplify", [](const StepRecord& r) { return r.volume_delta_simplify; });
  fn("volume_added", [](const StepRecord& r) { return r.volume_added; });
  if (!energy) return;  // not recorded: no placeholder columns of NaN
  fn("energy_m4", [](const StepRecord& r) { return r.energy_m4; });
  fn("energy_delta_erosion_m4", [](const StepRecord& r) { return r.energy_delta_erosion_m4; });
}

// ... and integer ones (int64).
template <typename Fn>
void for_each_integer_step_field(Fn&& fn) {
  fn("stamp", [](const StepRecord& r) { return static_cast<std::int64_t>(r.stamp); });
  fn("vertices", [](const StepRecord& r) { return static_cast<std::int64_t>(r.vertices); });
  fn("triangles", [](const StepRecord& r) { return static_cast<std::int64_t>(r.triangles); });
  fn("constrained_edges", [](const StepRecord& r) { return static_cast<std::int64_t>(r.constrained_edges); });
  fn("cells", [](const StepRecord& r) { return static_cast<std::int64_t>(r.cells); });
  fn("bytes", [](const StepRecord& r) { return static_cast<std::int64_t>(r.bytes); });
  fn("active", [](const StepRecord& r) { return static_cast<std::int64_t>(r.active); });
  fn("erosion_updates", [](const StepRecord& r) { return static_cast<std::int64_t>(r.erosion_updates); });
  fn("erosion_transfers", [](const StepRecord& r) { return static_cast<std::int64_t>(r.erosion_transfers); });
  fn("elements_touched", [](const StepRecord& r) { return static_cast<std::int64_t>(r.elements_touched); });
  fn("vertices_removed", [](const StepRecord& r) { return static_cast<std::int64_t>(r.removed); });
  fn("walk_steps", [](const StepRecord& r) { return static_cast<std::int64_t>(r.walk_steps); });
}

void write_contents(hid_t file, const RunResult& run, const PreparedScene& p, const Json& summary) {
  std::string overrides;
  for (const auto& o : p.scene.overrides) overrides += (overrides.empty() ? "" : "\n") + o;
  string_attribute(file, "scene_path", p.scene.path);
  string_attribute(file, "overrides", overrides);
  string_attribute(file, "backend", run.backend);
  string_attribute(file, "label", run.label);
  string_attribute(file, "version", kVersion);
  string_attribute(file, "commit", kCommit);
  string_attribute(file, "build_id", kBuildId);
  string_attribute(file, "compiler", std::string(kCompiler) + " " + kBuildType);
  string_attribute(file, "date", utc_now());
  string_attribute(file, "summary", summary.dump());
  {
    // The scene whole, whatever its size (a stroke of 10^6 waypoints is tens of MB).
    Handle scene = group(file, "scene");
    string_dataset(scene, "text", p.scene.text);
    string_dataset(scene, "resolved", p.scene.resolved);
  }
  {
    Handle steps = group(file, "steps");
    std::vector<double> column(run.steps.size());
    for_each_real_step_field(p.scene.output.energy, [&](const char* name, auto get) {
      for (std::size_t i = 0; i < run.steps.size(); ++i) column[i] = get(run.steps[i]);
      dataset(steps, name, H5T_NATIVE_DOUBLE, column.data(), {run.steps.size()});
    });
    std::vector<std::int64_t> integers(run.steps.size());
    for_each_integer_step_field([&](const char* name, auto get) {
      for (std::size_t i = 0; i < run.steps.size(); ++i) integers[i] = get(run.steps[i]);
      dataset(steps, name, H5T_NATIVE_INT64, integers.data(), {run.steps.size()}, H5T_STD_I64LE);
    });
  }
  {
    Handle g = group(file, "summary");
    for (const auto& [key, value] : summary.items()) {
      if (value.is_number_integer()) {
        const std::int64_t v = value.get<std::int64_t>();
        integer_attribute(g, key, H5T_STD_I64LE, H5T_NATIVE_INT64, &v);
      } else if (value.is_number()) {
        double_attribute(g, key, {value.get<double>()});
      } else if (value.is_boolean()) {
        const std::uint8_t v = value.get<bool>() ? 1 : 0;
        integer_attribute(g, key, H5T_STD_U8LE, H5T_NATIVE_UINT8, &v);
      } else if (value.is_string()) {
        string_attribute(g, key, value.get<std::string>());
      }
    }
  }
  {
    Handle g = group(file, "initial");
    raster_dataset(g, "raster", run.initial_raster);
  }
  Handle final_group = group(file, "final");
  raster_dataset(final_group, "raster", run.final_raster);
  Handle mesh = group(final_group, "mesh");
  MeshWriter writer(mesh);
  run.stream_final_mesh(writer);
}

// The in-memory file's buffer, allocated through HDF5's file image callbacks so that the
// finished image is written to disk from where the core driver built it: no second copy of
// a file that can be as large as the model (H5Fget_file_image would copy it).
struct CoreImage {
  void* data = nullptr;
  std::size_t size = 0;
};

void* image_malloc(std::size_t size, H5FD_file_image_op_t, void* udata) {
  auto* image = static_cast<CoreImage*>(udata);
  image->data = std::malloc(size);
  image->size = image->data ? size : 0;
  return image->data;
}

void* image_realloc(void* ptr, std::size_t size, H5FD_file_image_op_t, void* udata) {
  auto* image = static_cast<CoreImage*>(udata);
  void* grown = std::realloc(ptr, size);
  if (grown) {
    image->data = grown;
    image->size = size;
  }
  return grown;
}

herr_t image_free(void* ptr, H5FD_file_image_op_t, void* udata) {
  auto* image = static_cast<CoreImage*>(udata);
  if (ptr == image->data) *image = CoreImage{};
  std::free(ptr);
  return 0;
}

void* image_memcpy(void* dest, const void* src, std::size_t size, H5FD_file_image_op_t, void*) {
  return std::memcpy(dest, src, size);
}

// The property list's copies share the one CoreImage, which outlives them.
void* share_image(void* udata) { return udata; }
herr_t keep_image(void*) { return 0; }

// Reading.

// A string attribute or scalar dataset, variable-length or (files before 2026-11) fixed-length.
template <typename Read>
std::string read_string(hid_t type_of_object, const std::string& name, Read&& read) {
  Handle type(type_of_object, H5Tclose, "type of " + name);
  if (H5Tget_class(type) != H5T_STRING) return {};
  if (H5Tis_variable_str(type) > 0) {
    Handle mem(H5Tcopy(H5T_C_S1), H5Tclose, "copy string type");
    check(H5Tset_size(mem, H5T_VARIABLE), "size string");
    check(H5Tset_cset(mem, H5Tget_cset(type)), "set string encoding");  // HDF5 does not convert encodings
    char* data = nullptr;
    check(read(static_cast<hid_t>(mem), static_cast<void*>(&data)), "read " + name);
    std::string value = data ? data : "";
    H5free_memory(data);
    return value;
  }
  const std::size_t size = H5Tget_size(type);
  std::string value(size, '\0');
  Handle mem(H5Tcopy(H5T_C_S1), H5Tclose, "copy string type");
  check(H5Tset_size(mem, size), "size string");
  check(H5Tset_strpad(mem, H5T_STR_NULLPAD), "pad string");
  check(H5Tset_cset(mem, H5Tget_cset(type)), "set string encoding");
  check(read(static_cast<hid_t>(mem), static_cast<void*>(value.data())), "read " + name);
  value.resize(value.find_last_not_of('\0') + 1);
  return value;
}

std::string read_string_attribute(hid_t obj, const std::string& name) {
  Handle attr(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose, "open attribute " + name);
  return read_string(H5Aget_type(attr), name, [&](hid_t mem, void* buf) { return H5Aread(attr, mem, buf); });
}

std::string read_string_dataset(hid_t parent, const std::string& name) {
  Handle set(H5Dopen2(parent, name.c_str(), H5P_DEFAULT), H5Dclose, "open dataset " + name);
  Handle space(H5Dget_space(set), H5Sclose, "space of " + name);
  if (H5Sget_simple_extent_npoints(space) != 1) throw std::runtime_error(name + " is not a single string");
  return read_string(H5Dget_type(set), name,
                     [&](hid_t mem, void* buf) { return H5Dread(set, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf); });
}

std::vector<double> read_double_attribute(hid_t obj, const std::string& name) {
  Handle attr(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose, "open attribute " + name);
  Handle space(H5Aget_space(attr), H5Sclose, "space of " + name);
  std::vector<double> v(std::max<hssize_t>(1, H5Sget_simple_extent_npoints(space)));
  check(H5Aread(attr, H5T_NATIVE_DOUBLE, v.data()), "read attribute " + name);
  return v;
}

std::string exact_count(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f", v);
  return buf;
}

// The shape a dataset must have: its rank, and (when not 0) its last dimension.
struct Shape {
  int rank = 1;
  hsize_t columns = 0;
  std::string text;  // "n x 3", for messages
};

// Reads a numeric dataset whole after checking its shape, and that its declared size is one
// this process can hold (a small file can declare a huge chunked dataset): anything else is an
// InputError naming the dataset. `integers`: the file type must be an integer type (indices
// are never rounded from floating point).
template <typename T>
std::vector<T> read_dataset(hid_t parent, const std::string& name, hid_t mem_type, std::vector<hsize_t>& dims,
                            const Shape& shape, bool integers = false, double max_elements = 0.0) {
  Handle set(H5Dopen2(parent, name.c_str(), H5P_DEFAULT), H5Dclose, "open dataset " + name);
  Handle space(H5Dget_space(set), H5Sclose, "space of " + name);
  Handle type(H5Dget_type(set), H5Tclose, "type of " + name);
  const H5T_class_t cls = H5Tget_class(type);
  if (integers ? cls != H5T_INTEGER : (cls != H5T_FLOAT && cls != H5T_INTEGER))
    throw InputError(name + " must hold " + (integers ? "integers" : "numbers"));
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank != shape.rank)
    throw InputError(name + " must be a " + shape.text + " dataset (it has rank " + std::to_string(rank) + ")");
  dims.assign(static_cast<std::size_t>(rank), 0);
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  if (shape.columns != 0 && dims.back() != shape.columns)
    throw InputError(name + " must be a " + shape.text + " dataset (it has " + std::to_string(dims.back()) +
                     " columns)");
  double count = 1.0;
  for (hsize_t d : dims) count *= static_cast<double>(d);
  if (max_elements > 0.0 && count > max_elements)
    throw InputError(name + " declares " + exact_count(count) + " values, more than a run writes (at most " +
                     exact_count(max_elements) + ")");
  const std::optional<std::uint64_t> available = available_memory_bytes();
  if (available && count * sizeof(T) > static_cast<double>(*available))
    throw InputError(name + " declares " + exact_count(count) + " values (" + format_bytes(count * sizeof(T)) +
                     "), more than the memory available (" + format_bytes(static_cast<double>(*available)) + ")");
  set_out_of_memory_context(name + ": " + exact_count(count) + " values, " + format_bytes(count * sizeof(T)));
  std::vector<T> data(static_cast<std::size_t>(count));
  if (count > 0) check(H5Dread(set, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), "read " + name);
  return data;
}

// What a run file may hold: coordinates and heights within a scene's ranges (domain.origin_m
// and stroke.z_m within 1e9, domain.size_m at most 1e6), and a raster spacing that the
// coordinates can resolve (at least 1e-12 of the origin's magnitude, and 1e-9 m).
constexpr double kMaxMagnitude = 1e10;
// A stroke has at most 1e7 stamps and its settling at most 1e8 / 64 steps.
constexpr double kMaxStepRows = 2e7;
constexpr double kMinSpacing = 1e-9, kMaxSpacing = 1e7;

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// A raster whose shape, origin, spacing and values can be drawn and exported: anything else
// in a (hand-edited or damaged) file is an input error naming the dataset.
Raster read_raster(hid_t file, const std::string& name) {
  std::vector<hsize_t> dims;
  Raster r;
  r.values =
      read_dataset<double>(file, name, H5T_NATIVE_DOUBLE, dims, {2, 0, "2-D (rows along y)"}, false, kMaxRasterSamples);
  if (dims[0] < 2 || dims[1] < 2)
    throw InputError(name + " has " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) +
                     " values; a raster has at least 2 x 2");
  r.ny = dims[0];
  r.nx = dims[1];
  Handle set(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose, "open " + name);
  const auto origin = read_double_attribute(set, "origin_m");
  const auto spacing = read_double_attribute(set, "spacing_m");
  if (origin.size() != 2 || !(std::fabs(origin[0]) < kMaxMagnitude) || !(std::fabs(origin[1]) < kMaxMagnitude))
    throw InputError(name + ": attribute origin_m must be 2 finite numbers within (-1e10, 1e10) m");
  r.origin_m = Vec2(origin[0], origin[1]);
  r.spacing_m = spacing.at(0);
  const double finest = std::max(kMinSpacing, 1e-12 * r.origin_m.cwiseAbs().maxCoeff());
  if (spacing.size() != 1 || !(r.spacing_m >= finest) || !(r.spacing_m <= kMaxSpacing))
    throw InputError(name + ": attribute spacing_m = " + number_text(r.spacing_m) + " must be one number in [" +
                     number_text(finest) + ", 1e7] m (at least 1e-9 m and 1e-12 of the origin's magnitude)");
  const Vec2 far = r.point(r.nx - 1, r.ny - 1);
  if (!(std::fabs(far.x()) < kMaxMagnitude) || !(std::fabs(far.y()) < kMaxMagnitude))
    throw InputError(name + ": its " + std::to_string(r.ny) + " x " + std::to_string(r.nx) +
                     " samples at spacing_m = " + number_text(r.spacing_m) + " reach beyond (-1e10, 1e10) m");
  for (std::size_t i = 0; i < r.values.size(); ++i)
    if (!(std::fabs(r.values[i]) < kMaxMagnitude))
      throw InputError(name + ": value at row " + std::to_string(i / r.nx) + ", column " + std::to_string(i % r.nx) +
                       " = " + number_text(r.values[i]) + " is not a finite height within (-1e10, 1e10) m");
  return r;
}

// Vertex indices of a mesh dataset (triangles or constrained edges): each must name a vertex.
template <std::size_t N>
std::vector<std::array<std::uint32_t, N>> read_indices(hid_t file, const std::string& name, std::size_t vertices) {
  std::vector<hsize_t> dims;
  const auto raw = read_dataset<std::int64_t>(file, name, H5T_NATIVE_INT64, dims,
                                              {2, N, "n x " + std::to_string(N) + " (vertex indices)"}, true);
  std::vector<std::array<std::uint32_t, N>> out(dims[0]);
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const std::int64_t v = raw[i];
    if (v < 0 || static_cast<std::uint64_t>(v) >= vertices)
      throw InputError(name + ": row " + std::to_string(i / N) + " names vertex " + std::to_string(v) +
                       ", not one of the " + std::to_string(vertices) + " vertices (0 to " +
                       (vertices ? std::to_string(vertices - 1) : std::string("none")) + ")");
    out[i / N][i % N] = static_cast<std::uint32_t>(v);
  }
  return out;
}

herr_t collect_attribute_name(hid_t, const char* name, const H5A_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->emplace_back(name);
  return 0;
}

herr_t collect_link_name(hid_t, const char* name, const H5L_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->emplace_back(name);
  return 0;
}

}  // namespace

void write_run_file(const std::filesystem::path& path, const RunResult& run, const PreparedScene& prepared,
                    const Json& summary) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // failures become one exception, not pages of HDF5 stack
  // The file is assembled in memory (HDF5's core driver, no backing store) and then written
  // with plain I/O: a full disk is then our own write error. Were HDF5 writing to disk, a
  // failed flush would leave its file open, and HDF5's exit handler crashes on it.
  CoreImage image;
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "create file access properties");
  check(H5Pset_fapl_core(fapl, std::size_t{1} << 20, /*backing_store=*/0), "use the in-memory driver");
  H5FD_file_image_callbacks_t callbacks{image_malloc, image_memcpy, image_realloc, image_free,
                                        share_image,  keep_image,   &image};
  check(H5Pset_file_image_callbacks(fapl, &callbacks), "set the in-memory file's allocator");
  const std::string name = path.string() + ".in-memory";  // never touched on disk
  Handle file(H5Fcreate(name.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl), H5Fclose, "create " + path.string());
  write_contents(file, run, prepared, summary);
  check(H5Fflush(file, H5F_SCOPE_GLOBAL), "flush " + path.string());
  // The file's length (its end of allocation); the buffer may be shorter when the last bytes
  // were allocated but never written: the core driver reads those as zeros, and so do we.
  const ssize_t size = H5Fget_file_image(file, nullptr, 0);
  if (size < 0) throw std::runtime_error("HDF5: cannot size the file image of " + path.string());
  const std::size_t length = static_cast<std::size_t>(size), stored = std::min(length, image.size);
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::FILE* f = std::fopen(tmp.c_str(), "wb");
    bool ok = f && std::fwrite(image.data, 1, stored, f) == stored;
    for (std::size_t i = stored; ok && i < length; ++i) ok = std::fputc(0, f) != EOF;
    ok = ok && std::fflush(f) == 0;
    const int error = errno;
    if (f && std::fclose(f) != 0) ok = false;
    // Disk full, quota, read-only: the user's to fix (exit 2); write_atomically removes tmp.
    if (!ok)
      throw InputError("cannot write the run file " + path.string() + " (" + std::strerror(error ? error : errno) +
                       "); nothing was written");
  });
}

RunFile read_run_file(const std::filesystem::path& path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become exceptions, not stderr noise
  if (!std::filesystem::is_regular_file(path) || H5Fis_hdf5(path.c_str()) <= 0)
    throw InputError("run file " + path.string() + " does not exist or is not an HDF5 file");
  RunFile out;
  try {
    Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose, "open " + path.string());
    std::vector<std::string> names;
    H5Aiterate2(file, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_attribute_name, &names);
    for (const auto& n : names) out.attributes[n] = read_string_attribute(file, n);
    if (!out.attributes.count("backend") || !out.attributes.count("summary"))
      throw InputError("it is not a sandbench run file (no backend/summary attributes)");
    if (H5Lexists(file, "scene", H5P_DEFAULT) > 0) {
      out.attributes["scene_text"] = read_string_dataset(file, "/scene/text");
      out.attributes["scene_resolved"] = read_string_dataset(file, "/scene/resolved");
    }
    out.summary = Json::parse(out.attributes["summary"], nullptr, /*allow_exceptions=*/false);
    if (!out.summary.is_object()) throw InputError("attribute summary is not a JSON object");
    {
      Handle steps(H5Gopen2(file, "steps", H5P_DEFAULT), H5Gclose, "open /steps");
      std::vector<std::string> fields;
      H5Literate(steps, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_link_name, &fields);
      std::vector<hsize_t> dims;
      std::optional<std::size_t> rows;
      for (const auto& f : fields) {
        out.steps[f] = read_dataset<double>(steps, "/steps/" + f, H5T_NATIVE_DOUBLE, dims,
                                            {1, 0, "1-D (one value per step)"}, false, kMaxStepRows);
        if (rows && *rows != out.steps[f].size())
          throw InputError("/steps/" + f + " has " + std::to_string(out.steps[f].size()) +
                           " rows; the other steps have " + std::to_string(*rows));
        rows = out.steps[f].size();
      }
    }
    out.initial_raster = read_raster(file, "/initial/raster");
    out.final_raster = read_raster(file, "/final/raster");
    const Raster& a = out.initial_raster;
    const Raster& b = out.final_raster;
    if (a.nx != b.nx || a.ny != b.ny || a.origin_m != b.origin_m || a.spacing_m != b.spacing_m)
      throw InputError("/final/raster (" + std::to_string(b.ny) + " x " + std::to_string(b.nx) +
                       ") is not on the lattice of /initial/raster (" + std::to_string(a.ny) + " x " +
                       std::to_string(a.nx) + "): same shape, origin_m and spacing_m");
    std::vector<hsize_t> dims;
    const auto xyz =
        read_dataset<double>(file, "/final/mesh/vertices", H5T_NATIVE_DOUBLE, dims, {2, 3, "n x 3 (x, y, z)"});
    out.mesh.vertices.reserve(dims[0]);
    for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) {
      if (!(std::fabs(xyz[i]) < kMaxMagnitude) || !(std::fabs(xyz[i + 1]) < kMaxMagnitude) ||
          !(std::fabs(xyz[i + 2]) < kMaxMagnitude))
        throw InputError("/final/mesh/vertices: vertex " + std::to_string(i / 3) +
                         " is not finite within (-1e10, 1e10) m");
      out.mesh.vertices.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
    }
    const std::size_t n = out.mesh.vertices.size();
    // Indices must name vertices: renderers and exporters index with them.
    out.mesh.triangles = read_indices<3>(file, "/final/mesh/triangles", n);
    out.mesh.constrained_edges = read_indices<2>(file, "/final/mesh/constrained_edges", n);
    set_out_of_memory_context({});
  } catch (const InputError& e) {
    throw InputError("run file " + path.string() + ": " + e.what());
  } catch (const std::exception& e) {
    throw InputError("run file " + path.string() + " cannot be read: " + e.what());
  }
  return out;
}

}  // namespace sb
