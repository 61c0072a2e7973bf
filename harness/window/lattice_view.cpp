#include "harness/window/lattice_view.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <tuple>

#include "harness/window/gl_program.hpp"

namespace sb {

namespace {

// Vertex (i, j) of a patch (gl_VertexID = j * (cells.x + 1) + i) at node min(base + (i, j)
// stride, nodes - 1). On the patch's border, when a coarser patch surrounds it, the height is
// that patch's edge: linear between its vertices (multiples of `coarse`), so no crack opens.
constexpr const char* kLatticeVs = R"(#version 330 core
uniform sampler2D heights;
uniform ivec2 nodes;
uniform ivec2 cells;
uniform ivec2 base;
uniform int stride;
uniform int coarse;
uniform vec2 spacing;
uniform vec2 origin;  // node (0, 0) minus the view's origin
uniform float z_shift;
uniform mat4 view_projection;
out vec3 world;
float h(ivec2 n) { return texelFetch(heights, n, 0).r; }
float edge(ivec2 n, int axis) {
  int a = n[axis] / coarse * coarse;
  int b = min(a + coarse, nodes[axis] - 1);
  ivec2 na = n, nb = n;
  na[axis] = a;
  nb[axis] = b;
  float t = b > a ? float(n[axis] - a) / float(b - a) : 0.0;
  return mix(h(na), h(nb), t);
}
void main() {
  ivec2 v = ivec2(gl_VertexID % (cells.x + 1), gl_VertexID / (cells.x + 1));
  ivec2 n = min(base + v * stride, nodes - 1);
  float z = h(n);
  if (coarse > 0) {
    bool on_x = v.x == 0 || v.x == cells.x, on_y = v.y == 0 || v.y == cells.y;
    if (on_y && !on_x) z = edge(n, 0);
    if (on_x && !on_y) z = edge(n, 1);
  }
  world = vec3(origin + vec2(n) * spacing, z + z_shift);
  gl_Position = view_projection * vec4(world, 1.0);
})";

}  // namespace

LatticeSurface::LatticeSurface(const HeightLattice& lattice, const Vec3& origin, double z_ref)
    : lattice_(lattice), origin_(origin), z_ref_(z_ref) {
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
  if (lattice.nx > static_cast<std::size_t>(max_size) || lattice.ny > static_cast<std::size_t>(max_size))
    throw std::runtime_error("the grid has " + std::to_string(lattice.nx) + " x " + std::to_string(lattice.ny) +
                             " nodes; this OpenGL draws at most " + std::to_string(max_size) +
                             " a side (a larger grid.cell_m)");
  program_ = link_program(kLatticeVs, kSurfaceFragmentShader);
  std::tie(cells_x_, cells_y_) = lattice_patch_cells(lattice.nx, lattice.ny);

  glGenTextures(1, &texture_);
  glBindTexture(GL_TEXTURE_2D, texture_);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, static_cast<GLsizei>(lattice.nx), static_cast<GLsizei>(lattice.ny), 0, GL_RED,
               GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
  glBindTexture(GL_TEXTURE_2D, 0);

  // Two triangles per cell, row-major, counter-clockwise from above with the mesh's diagonal.
  std::vector<std::uint32_t> indices;
  indices.reserve(cells_x_ * cells_y_ * 6);
  const auto row = static_cast<std::uint32_t>(cells_x_ + 1);
  for (std::uint32_t j = 0; j < cells_y_; ++j)
    for (std::uint32_t i = 0; i < cells_x_; ++i) {
      const std::uint32_t a = j * row + i, b = a + 1, c = a + row, d = c + 1;
      indices.insert(indices.end(), {a, b, d, a, d, c});
    }
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &ebo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo_);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(std::uint32_t)), indices.data(),
               GL_STATIC_DRAW);
  glBindVertexArray(0);
}

LatticeSurface::~LatticeSurface() {
  glDeleteBuffers(1, &ebo_);
  glDeleteVertexArrays(1, &vao_);
  glDeleteTextures(1, &texture_);
  glDeleteProgram(program_);
}

void LatticeSurface::upload(const LatticeUpdate& u) {
  glBindTexture(GL_TEXTURE_2D, texture_);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  std::size_t offset = 0;
  for (const NodeRect& r : u.rects) {
    const std::size_t w = r.x1 - r.x0, h = r.y1 - r.y0;
    glTexSubImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(r.x0), static_cast<GLint>(r.y0), static_cast<GLsizei>(w),
                    static_cast<GLsizei>(h), GL_RED, GL_FLOAT, u.heights.data() + offset);
    offset += w * h;
  }
  glBindTexture(GL_TEXTURE_2D, 0);
}

void LatticeSurface::draw_cells(std::size_t first_cell, std::size_t cells) {
  if (cells == 0) return;
  counts_.push_back(static_cast<int>(cells * 6));
  offsets_.push_back(reinterpret_cast<const void*>(first_cell * 6 * sizeof(std::uint32_t)));
  triangles_ += 2 * cells;
}

void LatticeSurface::draw(const Vec2& focus) {
  const auto node = [](double p, double lo, double d, std::size_t n) {
    const double f = std::round((p - lo) / d);
    return static_cast<std::size_t>(std::clamp(std::isfinite(f) ? f : 0.0, 0.0, static_cast<double>(n - 1)));
  };
  const std::size_t fx = node(focus.x(), lattice_.origin.x(), lattice_.dx, lattice_.nx);
  const std::size_t fy = node(focus.y(), lattice_.origin.y(), lattice_.dy, lattice_.ny);
  glUseProgram(program_);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, texture_);
  glUniform1i(glGetUniformLocation(program_, "heights"), 0);
  glUniform2i(glGetUniformLocation(program_, "nodes"), static_cast<GLint>(lattice_.nx),
              static_cast<GLint>(lattice_.ny));
  glUniform2i(glGetUniformLocation(program_, "cells"), static_cast<GLint>(cells_x_), static_cast<GLint>(cells_y_));
  glUniform2f(glGetUniformLocation(program_, "spacing"), static_cast<float>(lattice_.dx),
              static_cast<float>(lattice_.dy));
  glUniform2f(glGetUniformLocation(program_, "origin"), static_cast<float>(lattice_.origin.x() - origin_.x()),
              static_cast<float>(lattice_.origin.y() - origin_.y()));
  glUniform1f(glGetUniformLocation(program_, "z_shift"), static_cast<float>(z_ref_ - origin_.z()));
  const int base = glGetUniformLocation(program_, "base"), stride = glGetUniformLocation(program_, "stride"),
            coarse = glGetUniformLocation(program_, "coarse");
  glBindVertexArray(vao_);
  triangles_ = 0;
  for (const LatticePatch& p : lattice_patches(lattice_.nx, lattice_.ny, fx, fy)) {
    glUniform2i(base, static_cast<GLint>(p.x0), static_cast<GLint>(p.y0));
    glUniform1i(stride, static_cast<GLint>(p.stride));
    glUniform1i(coarse, static_cast<GLint>(p.coarse));
    counts_.clear();
    offsets_.clear();
    if (p.hx0 == p.hx1 || p.hy0 == p.hy1) {
      draw_cells(0, cells_x_ * cells_y_);
    } else {  // the rows below the hole, beside it on each side, above it
      draw_cells(0, p.hy0 * cells_x_);
      for (std::size_t j = p.hy0; j < p.hy1; ++j) {
        draw_cells(j * cells_x_, p.hx0);
        draw_cells(j * cells_x_ + p.hx1, cells_x_ - p.hx1);
      }
      draw_cells(p.hy1 * cells_x_, (cells_y_ - p.hy1) * cells_x_);
    }
    glMultiDrawElements(GL_TRIANGLES, counts_.data(), GL_UNSIGNED_INT, offsets_.data(),
                        static_cast<GLsizei>(counts_.size()));
  }
  glBindVertexArray(0);
  glBindTexture(GL_TEXTURE_2D, 0);
}

}  // namespace sb
