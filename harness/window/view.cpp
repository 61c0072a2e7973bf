#include "harness/window/view.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "harness/window/gl_program.hpp"

namespace sb {

namespace {

constexpr const char* kSurfaceVs = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 view_projection;
out vec3 world;
void main() {
  world = position;
  gl_Position = view_projection * vec4(position, 1.0);
})";

constexpr const char* kLineVs = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 rgb;
uniform mat4 view_projection;
out vec3 c;
void main() {
  c = rgb;
  gl_Position = view_projection * vec4(position, 1.0);
})";

constexpr const char* kLineFs = R"(#version 330 core
in vec3 c;
out vec4 colour;
void main() { colour = vec4(c, 1.0); })";

}  // namespace

TerrainView::TerrainView(const Vec3& origin, double z_lo, double z_hi) : origin_(origin), z_lo_(z_lo), z_hi_(z_hi) {
  surface_program_ = link_program(kSurfaceVs, kSurfaceFragmentShader);
  line_program_ = link_program(kLineVs, kLineFs);
  glGenVertexArrays(1, &mesh_vao_);
  glGenBuffers(1, &mesh_vbo_);
  glGenBuffers(1, &mesh_ebo_);
  glBindVertexArray(mesh_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, mesh_vbo_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh_ebo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glGenVertexArrays(1, &line_vao_);
  glGenBuffers(1, &line_vbo_);
  glBindVertexArray(line_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex), reinterpret_cast<const void*>(3 * sizeof(float)));
  glBindVertexArray(0);
}

TerrainView::~TerrainView() {
  lattice_.reset();
  mesh_tiles_.reset();
  glDeleteBuffers(1, &mesh_vbo_);
  glDeleteBuffers(1, &mesh_ebo_);
  glDeleteBuffers(1, &line_vbo_);
  glDeleteVertexArrays(1, &mesh_vao_);
  glDeleteVertexArrays(1, &line_vao_);
  glDeleteProgram(surface_program_);
  glDeleteProgram(line_program_);
}

void TerrainView::upload_mesh(const SurfaceMesh& mesh) {
  std::vector<float> xyz;
  xyz.reserve(mesh.vertices.size() * 3);
  for (const Vec3& v : mesh.vertices) {
    const Vec3 p = v - origin_;
    xyz.insert(xyz.end(), {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
  }
  glBindVertexArray(mesh_vao_);
  glBindBuffer(GL_ARRAY_BUFFER, mesh_vbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(xyz.size() * sizeof(float)), xyz.data(), GL_DYNAMIC_DRAW);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.triangles.size() * 3 * sizeof(std::uint32_t)),
               mesh.triangles.data(), GL_DYNAMIC_DRAW);
  glBindVertexArray(0);
  mesh_indices_ = static_cast<int>(mesh.triangles.size() * 3);
}

void TerrainView::use_lattice(const HeightLattice& lattice, double z_ref) {
  lattice_ = std::make_unique<LatticeSurface>(lattice, origin_, z_ref);
}

void TerrainView::upload_lattice(const LatticeUpdate& update) {
  if (lattice_) lattice_->upload(update);
}

void TerrainView::use_mesh_tiles(std::size_t tiles, const Vec3& feed_origin) {
  mesh_tiles_ = std::make_unique<MeshTileSurface>(tiles, feed_origin - origin_);
}

void TerrainView::upload_mesh_tiles(const MeshTileUpdate& update) {
  if (mesh_tiles_) mesh_tiles_->upload(update);
}

void TerrainView::draw(const Camera& camera, int width, int height, bool wireframe,
                       const std::vector<LineVertex>& lines, const Vec2& focus) {
  glViewport(0, 0, width, height);
  glClearColor(0.16f, 0.18f, 0.22f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  const Eigen::Matrix4f vp = camera.view_projection(static_cast<double>(width) / std::max(height, 1), origin_);

  const unsigned program = lattice_ ? lattice_->program() : surface_program_;
  glUseProgram(program);
  glUniformMatrix4fv(glGetUniformLocation(program, "view_projection"), 1, GL_FALSE, vp.data());
  glUniform2f(glGetUniformLocation(program, "z_range"), static_cast<float>(z_lo_ - origin_.z()),
              static_cast<float>(z_hi_ - origin_.z()));
  const Vec3 light = light_direction();
  glUniform3f(glGetUniformLocation(program, "light"), static_cast<float>(light.x()), static_cast<float>(light.y()),
              static_cast<float>(light.z()));
  glUniform2f(glGetUniformLocation(program, "ambient_diffuse"), static_cast<float>(kAmbient),
              static_cast<float>(kDiffuse));
  const int tint = glGetUniformLocation(program, "tint");
  const auto surface = [&] {
    if (lattice_) {
      lattice_->draw(focus);
    } else if (mesh_tiles_) {
      mesh_tiles_->draw();
    } else {
      glBindVertexArray(mesh_vao_);
      glDrawElements(GL_TRIANGLES, mesh_indices_, GL_UNSIGNED_INT, nullptr);
    }
  };
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 1.0f);
  glUniform4f(tint, 0, 0, 0, 0);
  surface();
  glDisable(GL_POLYGON_OFFSET_FILL);
  if (wireframe) {
    glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    glUniform4f(tint, 0.25f, 0.2f, 0.12f, 1.0f);
    surface();
    glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  }

  if (!lines.empty()) {
    glUseProgram(line_program_);
    glUniformMatrix4fv(glGetUniformLocation(line_program_, "view_projection"), 1, GL_FALSE, vp.data());
    std::vector<LineVertex> shifted = lines;
    for (LineVertex& v : shifted) {
      v.x -= static_cast<float>(origin_.x());
      v.y -= static_cast<float>(origin_.y());
      v.z -= static_cast<float>(origin_.z());
    }
    glBindVertexArray(line_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(shifted.size() * sizeof(LineVertex)), shifted.data(),
                 GL_STREAM_DRAW);
    glDisable(GL_DEPTH_TEST);  // the tool stays visible inside the sand
    glDrawArrays(GL_LINES, 0, static_cast<int>(shifted.size()));
    glEnable(GL_DEPTH_TEST);
  }
  glBindVertexArray(0);
  glUseProgram(0);
}

std::vector<std::uint8_t> TerrainView::read_pixels(int width, int height) const {
  std::vector<std::uint8_t> rows(static_cast<std::size_t>(width) * height * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  std::vector<std::uint8_t> flipped(rows.size());
  const std::size_t stride = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height; ++y)
    std::copy_n(rows.data() + static_cast<std::size_t>(height - 1 - y) * stride, stride,
                flipped.data() + static_cast<std::size_t>(y) * stride);
  return flipped;
}

}  // namespace sb
