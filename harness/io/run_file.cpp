#include "harness/io/run_file.hpp"

#include <hdf5.h>

#include <chrono>
#include <ctime>
#include <optional>
#include <span>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/input_error.hpp"
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

void string_attribute(hid_t obj, const std::string& name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "copy string type");
  check(H5Tset_size(type, std::max<std::size_t>(1, value.size())), "size string");
  check(H5Tset_strpad(type, H5T_STR_NULLPAD), "pad string");
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "create scalar space");
  Handle attr(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              "create attribute " + name);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  check(H5Awrite(attr, type, padded.data()), "write attribute " + name);
}

void double_attribute(hid_t obj, const std::string& name, const std::vector<double>& values) {
  const hsize_t n = values.size();
  Handle space(n == 1 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose, "create space");
  Handle attr(H5Acreate2(obj, name.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              "create attribute " + name);
  check(H5Awrite(attr, H5T_NATIVE_DOUBLE, values.data()), "write attribute " + name);
}

// Creates a dataset of the given shape, chunked and compressed when large.
Handle create_dataset(hid_t parent, const std::string& name, hid_t mem_type, const std::vector<hsize_t>& dims) {
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose, "create space");
  Handle plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "create property list");
  std::size_t count = 1;
  for (hsize_t d : dims) count *= d;
  if (count > 4096) {  // chunk and compress large arrays
    std::vector<hsize_t> chunk = dims;
    chunk[0] = std::min<hsize_t>(dims[0], std::max<hsize_t>(1, 65536 / std::max<hsize_t>(1, count / dims[0])));
    check(H5Pset_chunk(plist, static_cast<int>(chunk.size()), chunk.data()), "chunk " + name);
    check(H5Pset_deflate(plist, 4), "compress " + name);
  }
  return Handle(H5Dcreate2(parent, name.c_str(), mem_type, space, H5P_DEFAULT, plist, H5P_DEFAULT), H5Dclose,
                "create dataset " + name);
}

template <typename T>
void dataset(hid_t parent, const std::string& name, hid_t mem_type, const T* data, std::vector<hsize_t> dims) {
  Handle set = create_dataset(parent, name, mem_type, dims);
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

// Step fields by name, in the order they are written.
template <typename Fn>
void for_each_step_field(Fn&& fn) {
  fn("stamp", [](const StepRecord& r) { return static_cast<double>(r.stamp); });
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
  fn("vertices", [](const StepRecord& r) { return static_cast<double>(r.vertices); });
  fn("triangles", [](const StepRecord& r) { return static_cast<double>(r.triangles); });
  fn("constrained_edges", [](const StepRecord& r) { return static_cast<double>(r.constrained_edges); });
  fn("cells", [](const StepRecord& r) { return static_cast<double>(r.cells); });
  fn("bytes", [](const StepRecord& r) { return static_cast<double>(r.bytes); });
  fn("active", [](const StepRecord& r) { return static_cast<double>(r.active); });
  fn("erosion_updates", [](const StepRecord& r) { return static_cast<double>(r.erosion_updates); });
  fn("erosion_transfers", [](const StepRecord& r) { return static_cast<double>(r.erosion_transfers); });
  fn("elements_touched", [](const StepRecord& r) { return static_cast<double>(r.elements_touched); });
  fn("vertices_removed", [](const StepRecord& r) { return static_cast<double>(r.removed); });
  fn("walk_steps", [](const StepRecord& r) { return static_cast<double>(r.walk_steps); });
  fn("energy_m4", [](const StepRecord& r) { return r.energy_m4; });
  fn("energy_delta_erosion_m4", [](const StepRecord& r) { return r.energy_delta_erosion_m4; });
}

void write_contents(hid_t file, const RunResult& run, const PreparedScene& p, const Json& summary) {
  std::string overrides;
  for (const auto& o : p.scene.overrides) overrides += (overrides.empty() ? "" : "\n") + o;
  string_attribute(file, "scene_text", p.scene.text);
  string_attribute(file, "scene_resolved", p.scene.resolved);
  string_attribute(file, "scene_path", p.scene.path);
  string_attribute(file, "overrides", overrides);
  string_attribute(file, "backend", run.backend);
  string_attribute(file, "label", run.label);
  string_attribute(file, "parameters", p.scene.resolved);
  string_attribute(file, "version", kVersion);
  string_attribute(file, "commit", kCommit);
  string_attribute(file, "build_id", kBuildId);
  string_attribute(file, "compiler", std::string(kCompiler) + " " + kBuildType);
  string_attribute(file, "date", utc_now());
  string_attribute(file, "summary", summary.dump());

  {
    Handle steps = group(file, "steps");
    std::vector<double> column(run.steps.size());
    for_each_step_field([&](const char* name, auto get) {
      for (std::size_t i = 0; i < run.steps.size(); ++i) column[i] = get(run.steps[i]);
      dataset(steps, name, H5T_NATIVE_DOUBLE, column.data(), {run.steps.size()});
    });
  }
  {
    Handle g = group(file, "summary");
    for (const auto& [key, value] : summary.items()) {
      if (value.is_number())
        double_attribute(g, key, {value.get<double>()});
      else if (value.is_boolean())
        double_attribute(g, key, {value.get<bool>() ? 1.0 : 0.0});
      else if (value.is_string())
        string_attribute(g, key, value.get<std::string>());
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

// Reading.

std::string read_string_attribute(hid_t obj, const std::string& name) {
  Handle attr(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose, "open attribute " + name);
  Handle type(H5Aget_type(attr), H5Tclose, "type of " + name);
  if (H5Tget_class(type) != H5T_STRING) return {};
  const std::size_t size = H5Tget_size(type);
  std::string value(size, '\0');
  Handle mem(H5Tcopy(H5T_C_S1), H5Tclose, "copy string type");
  check(H5Tset_size(mem, size), "size string");
  check(H5Tset_strpad(mem, H5T_STR_NULLPAD), "pad string");
  check(H5Aread(attr, mem, value.data()), "read attribute " + name);
  value.resize(value.find_last_not_of('\0') + 1);
  return value;
}

std::vector<double> read_double_attribute(hid_t obj, const std::string& name) {
  Handle attr(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose, "open attribute " + name);
  Handle space(H5Aget_space(attr), H5Sclose, "space of " + name);
  std::vector<double> v(std::max<hssize_t>(1, H5Sget_simple_extent_npoints(space)));
  check(H5Aread(attr, H5T_NATIVE_DOUBLE, v.data()), "read attribute " + name);
  return v;
}

template <typename T>
std::vector<T> read_dataset(hid_t parent, const std::string& name, hid_t mem_type, std::vector<hsize_t>& dims) {
  Handle set(H5Dopen2(parent, name.c_str(), H5P_DEFAULT), H5Dclose, "open dataset " + name);
  Handle space(H5Dget_space(set), H5Sclose, "space of " + name);
  dims.assign(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)), 0);
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  std::size_t count = 1;
  for (hsize_t d : dims) count *= d;
  std::vector<T> data(count);
  if (count > 0) check(H5Dread(set, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), "read " + name);
  return data;
}

Raster read_raster(hid_t file, const std::string& name) {
  std::vector<hsize_t> dims;
  Raster r;
  r.values = read_dataset<double>(file, name, H5T_NATIVE_DOUBLE, dims);
  if (dims.size() != 2) throw std::runtime_error(name + " is not 2-D");
  r.ny = dims[0];
  r.nx = dims[1];
  Handle set(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose, "open " + name);
  const auto origin = read_double_attribute(set, "origin_m");
  r.origin_m = Vec2(origin.at(0), origin.at(1));
  r.spacing_m = read_double_attribute(set, "spacing_m").at(0);
  return r;
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
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose, "create " + tmp.string());
    write_contents(file, run, prepared, summary);
    check(H5Fflush(file, H5F_SCOPE_GLOBAL), "flush " + tmp.string());
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
      throw InputError("run file " + path.string() + " is not a sandbench run file (no backend/summary attributes)");
    out.summary = Json::parse(out.attributes["summary"]);
    {
      Handle steps(H5Gopen2(file, "steps", H5P_DEFAULT), H5Gclose, "open /steps");
      std::vector<std::string> fields;
      H5Literate(steps, H5_INDEX_NAME, H5_ITER_INC, nullptr, collect_link_name, &fields);
      std::vector<hsize_t> dims;
      for (const auto& f : fields) out.steps[f] = read_dataset<double>(steps, f, H5T_NATIVE_DOUBLE, dims);
    }
    out.initial_raster = read_raster(file, "/initial/raster");
    out.final_raster = read_raster(file, "/final/raster");
    std::vector<hsize_t> dims;
    const auto xyz = read_dataset<double>(file, "/final/mesh/vertices", H5T_NATIVE_DOUBLE, dims);
    for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) out.mesh.vertices.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
    const auto tri = read_dataset<std::uint32_t>(file, "/final/mesh/triangles", H5T_NATIVE_UINT32, dims);
    for (std::size_t i = 0; i + 2 < tri.size(); i += 3) out.mesh.triangles.push_back({tri[i], tri[i + 1], tri[i + 2]});
    const auto ce = read_dataset<std::uint32_t>(file, "/final/mesh/constrained_edges", H5T_NATIVE_UINT32, dims);
    for (std::size_t i = 0; i + 1 < ce.size(); i += 2) out.mesh.constrained_edges.push_back({ce[i], ce[i + 1]});
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError("run file " + path.string() + " cannot be read: " + e.what());
  }
  return out;
}

}  // namespace sb
