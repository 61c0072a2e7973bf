#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "common/input_error.hpp"
#include "harness/io/export.hpp"

namespace sb {

namespace {
static_assert(std::endian::native == std::endian::little, "PLY export writes little-endian from memory");

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  return s;
}

// Triangles turned counter-clockwise seen from above (the surface is a height field).
std::vector<std::array<std::uint32_t, 3>> upward(const SurfaceMesh& m) {
  std::vector<std::array<std::uint32_t, 3>> out;
  out.reserve(m.triangles.size());
  for (auto t : m.triangles) {
    if (t[0] >= m.vertices.size() || t[1] >= m.vertices.size() || t[2] >= m.vertices.size())
      throw std::invalid_argument("export: triangle index out of range");
    const Vec3 &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
    if (cross2((b - a).head<2>(), (c - a).head<2>()) < 0.0) std::swap(t[1], t[2]);
    out.push_back(t);
  }
  return out;
}

std::uint64_t key(std::uint32_t a, std::uint32_t b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
}

struct Edge {
  std::uint32_t a, b;
  std::uint8_t constrained;
};

// Every unique edge of the triangles plus any constrained edge not among them, sorted.
std::vector<Edge> edges(const std::vector<std::array<std::uint32_t, 3>>& triangles, const SurfaceMesh& m) {
  std::vector<std::uint64_t> keys;
  keys.reserve(3 * triangles.size() + m.constrained_edges.size());
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k) keys.push_back(key(t[k], t[(k + 1) % 3]));
  std::vector<std::uint64_t> constrained;
  for (const auto& e : m.constrained_edges) {
    if (e[0] >= m.vertices.size() || e[1] >= m.vertices.size())
      throw std::invalid_argument("export: constrained edge index out of range");
    constrained.push_back(key(e[0], e[1]));
  }
  keys.insert(keys.end(), constrained.begin(), constrained.end());
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  std::sort(constrained.begin(), constrained.end());
  std::vector<Edge> out;
  out.reserve(keys.size());
  for (std::uint64_t k : keys)
    out.push_back({static_cast<std::uint32_t>(k >> 32), static_cast<std::uint32_t>(k & 0xffffffffu),
                   static_cast<std::uint8_t>(std::binary_search(constrained.begin(), constrained.end(), k))});
  return out;
}

template <typename T>
void put(std::string& out, T v) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));
  out.append(bytes, sizeof(T));
}

}  // namespace

const std::map<std::string, ExportFormat>& export_formats() {
  static const std::map<std::string, ExportFormat> table = {
      {"ply", ExportFormat::Ply}, {"obj", ExportFormat::Obj}, {"png16", ExportFormat::Png16}};
  return table;
}

void export_ply(const std::filesystem::path& file, const SurfaceMesh& mesh, const std::vector<std::string>& comments) {
  const auto triangles = upward(mesh);
  const auto all_edges = edges(triangles, mesh);
  std::string out = "ply\nformat binary_little_endian 1.0\n";
  for (const auto& c : comments) out += "comment " + one_line(c) + "\n";
  out += "comment units metres, z up; edge constrained = 1 for constrained edges\n";
  out += "element vertex " + std::to_string(mesh.vertices.size()) +
         "\nproperty float x\nproperty float y\nproperty float z\n";
  out += "element face " + std::to_string(triangles.size()) + "\nproperty list uchar int vertex_indices\n";
  out += "element edge " + std::to_string(all_edges.size()) +
         "\nproperty int vertex1\nproperty int vertex2\nproperty uchar constrained\nend_header\n";
  out.reserve(out.size() + 12 * mesh.vertices.size() + 13 * triangles.size() + 9 * all_edges.size());
  for (const Vec3& p : mesh.vertices) {
    put(out, static_cast<float>(p.x()));
    put(out, static_cast<float>(p.y()));
    put(out, static_cast<float>(p.z()));
  }
  for (const auto& t : triangles) {
    put(out, std::uint8_t{3});
    for (std::uint32_t v : t) put(out, static_cast<std::int32_t>(v));
  }
  for (const Edge& e : all_edges) {
    put(out, static_cast<std::int32_t>(e.a));
    put(out, static_cast<std::int32_t>(e.b));
    put(out, e.constrained);
  }
  write_text_atomically(file, out);
}

void export_obj(const std::filesystem::path& file, const SurfaceMesh& mesh, const std::vector<std::string>& comments) {
  const auto triangles = upward(mesh);
  std::string out;
  for (const auto& c : comments) out += "# " + one_line(c) + "\n";
  out += "# units metres, z up (Blender: import with Up Axis = Z)\n";
  out += "# " + std::to_string(mesh.vertices.size()) + " vertices, " + std::to_string(triangles.size()) +
         " triangles, " + std::to_string(mesh.constrained_edges.size()) + " constrained edges\n";
  out += "o terrain\n";
  out.reserve(out.size() + 40 * mesh.vertices.size() + 24 * triangles.size());
  for (const Vec3& p : mesh.vertices) {
    out += "v ";
    out += exact_number(p.x());
    out += ' ';
    out += exact_number(p.y());
    out += ' ';
    out += exact_number(p.z());
    out += '\n';
  }
  for (const auto& t : triangles)
    out += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1) + "\n";
  if (!mesh.constrained_edges.empty()) {
    out += "g constrained_edges\n";
    for (const auto& e : mesh.constrained_edges) {
      if (e[0] >= mesh.vertices.size() || e[1] >= mesh.vertices.size())
        throw std::invalid_argument("export: constrained edge index out of range");
      out += "l " + std::to_string(e[0] + 1) + " " + std::to_string(e[1] + 1) + "\n";
    }
  }
  write_text_atomically(file, out);
}

}  // namespace sb
