#include "harness/window/view.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace sb {

namespace {

const char* kSurfaceVs = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 view_projection;
out vec3 world;
void main() {
  world = position;
  gl_Position = view_projection * vec4(position, 1.0);
})";

// Facet normals from screen-space derivatives: every triangle shows as it is.
const char* kSurfaceFs = R"(#version 330 core
in vec3 world;
uniform vec2 z_range;
uniform vec4 tint;
out vec4 colour;
void main() {
  if (tint.a > 0.0) { colour = tint; return; }
  vec3 n = normalize(cross(dFdx(world), dFdy(world)));
  if (n.z < 0.0) n = -n;
  float h = clamp((world.z - z_range.x) / max(z_range.y - z_range.x, 1e-6), 0.0, 1.0);
  vec3 low = vec3(0.55, 0.42, 0.26), high = vec3(0.93, 0.82, 0.60);
  vec3 base = mix(low, high, h);
  vec3 light = normalize(vec3(-0.45, -0.3, 0.85));
  float diffuse = max(dot(n, light), 0.0);
  colour = vec4(base * (0.30 + 0.75 * diffuse), 1.0);
})";

const char* kLineVs = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 rgb;
uniform mat4 view_projection;
out vec3 c;
void main() {
  c = rgb;
  gl_Position = view_projection * vec4(position, 1.0);
})";

const char* kLineFs = R"(#version 330 core
in vec3 c;
out vec4 colour;
void main() { colour = vec4(c, 1.0); })";

unsigned compile(const gl::Api& gl, GLenum type, const char* source) {
  const unsigned s = gl.CreateShader(type);
  gl.ShaderSource(s, 1, &source, nullptr);
  gl.CompileShader(s);
  GLint ok = 0;
  gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    gl.GetShaderInfoLog(s, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("OpenGL shader: ") + log);
  }
  return s;
}

unsigned link(const gl::Api& gl, const char* vs, const char* fs) {
  const unsigned v = compile(gl, GL_VERTEX_SHADER, vs), f = compile(gl, GL_FRAGMENT_SHADER, fs);
  const unsigned p = gl.CreateProgram();
  gl.AttachShader(p, v);
  gl.AttachShader(p, f);
  gl.LinkProgram(p);
  gl.DeleteShader(v);
  gl.DeleteShader(f);
  GLint ok = 0;
  gl.GetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    gl.GetProgramInfoLog(p, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("OpenGL program: ") + log);
  }
  return p;
}

}  // namespace

TerrainView::TerrainView(const gl::Api& api, const Vec3& origin, double z_lo, double z_hi)
    : gl_(api), origin_(origin), z_lo_(z_lo), z_hi_(z_hi) {
  surface_program_ = link(gl_, kSurfaceVs, kSurfaceFs);
  line_program_ = link(gl_, kLineVs, kLineFs);
  gl_.GenVertexArrays(1, &mesh_vao_);
  gl_.GenBuffers(1, &mesh_vbo_);
  gl_.GenBuffers(1, &mesh_ebo_);
  gl_.BindVertexArray(mesh_vao_);
  gl_.BindBuffer(GL_ARRAY_BUFFER, mesh_vbo_);
  gl_.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh_ebo_);
  gl_.EnableVertexAttribArray(0);
  gl_.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  gl_.GenVertexArrays(1, &line_vao_);
  gl_.GenBuffers(1, &line_vbo_);
  gl_.BindVertexArray(line_vao_);
  gl_.BindBuffer(GL_ARRAY_BUFFER, line_vbo_);
  gl_.EnableVertexAttribArray(0);
  gl_.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex), nullptr);
  gl_.EnableVertexAttribArray(1);
  gl_.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex),
                          reinterpret_cast<const void*>(3 * sizeof(float)));
  gl_.BindVertexArray(0);
}

TerrainView::~TerrainView() {
  gl_.DeleteBuffers(1, &mesh_vbo_);
  gl_.DeleteBuffers(1, &mesh_ebo_);
  gl_.DeleteBuffers(1, &line_vbo_);
  gl_.DeleteVertexArrays(1, &mesh_vao_);
  gl_.DeleteVertexArrays(1, &line_vao_);
  gl_.DeleteProgram(surface_program_);
  gl_.DeleteProgram(line_program_);
}

void TerrainView::upload_mesh(const SurfaceMesh& mesh) {
  std::vector<float> xyz;
  xyz.reserve(mesh.vertices.size() * 3);
  for (const Vec3& v : mesh.vertices) {
    const Vec3 p = v - origin_;
    xyz.insert(xyz.end(), {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())});
  }
  gl_.BindVertexArray(mesh_vao_);
  gl_.BindBuffer(GL_ARRAY_BUFFER, mesh_vbo_);
  gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(xyz.size() * sizeof(float)), xyz.data(), GL_DYNAMIC_DRAW);
  gl_.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.triangles.size() * 3 * sizeof(std::uint32_t)),
                 mesh.triangles.data(), GL_DYNAMIC_DRAW);
  gl_.BindVertexArray(0);
  mesh_indices_ = static_cast<int>(mesh.triangles.size() * 3);
}

void TerrainView::draw(const Camera& camera, int width, int height, bool wireframe,
                       const std::vector<LineVertex>& lines) {
  gl_.Viewport(0, 0, width, height);
  gl_.ClearColor(0.16f, 0.18f, 0.22f, 1.0f);
  gl_.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  gl_.Enable(GL_DEPTH_TEST);
  gl_.DepthFunc(GL_LEQUAL);
  const Eigen::Matrix4f vp = camera.view_projection(static_cast<double>(width) / std::max(height, 1), origin_);

  gl_.UseProgram(surface_program_);
  gl_.UniformMatrix4fv(gl_.GetUniformLocation(surface_program_, "view_projection"), 1, GL_FALSE, vp.data());
  gl_.Uniform2f(gl_.GetUniformLocation(surface_program_, "z_range"), static_cast<float>(z_lo_ - origin_.z()),
                static_cast<float>(z_hi_ - origin_.z()));
  const int tint = gl_.GetUniformLocation(surface_program_, "tint");
  gl_.BindVertexArray(mesh_vao_);
  gl_.Enable(GL_POLYGON_OFFSET_FILL);
  gl_.PolygonOffset(1.0f, 1.0f);
  gl_.Uniform4f(tint, 0, 0, 0, 0);
  gl_.DrawElements(GL_TRIANGLES, mesh_indices_, GL_UNSIGNED_INT, nullptr);
  gl_.Disable(GL_POLYGON_OFFSET_FILL);
  if (wireframe) {
    gl_.PolygonMode(GL_FRONT_AND_BACK, GL_LINE);
    gl_.Uniform4f(tint, 0.25f, 0.2f, 0.12f, 1.0f);
    gl_.DrawElements(GL_TRIANGLES, mesh_indices_, GL_UNSIGNED_INT, nullptr);
    gl_.PolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  }

  if (!lines.empty()) {
    gl_.UseProgram(line_program_);
    gl_.UniformMatrix4fv(gl_.GetUniformLocation(line_program_, "view_projection"), 1, GL_FALSE, vp.data());
    std::vector<LineVertex> shifted = lines;
    for (LineVertex& v : shifted) {
      v.x -= static_cast<float>(origin_.x());
      v.y -= static_cast<float>(origin_.y());
      v.z -= static_cast<float>(origin_.z());
    }
    gl_.BindVertexArray(line_vao_);
    gl_.BindBuffer(GL_ARRAY_BUFFER, line_vbo_);
    gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(shifted.size() * sizeof(LineVertex)), shifted.data(),
                   GL_STREAM_DRAW);
    gl_.Disable(GL_DEPTH_TEST);  // the tool stays visible inside the sand
    gl_.DrawArrays(GL_LINES, 0, static_cast<int>(shifted.size()));
    gl_.Enable(GL_DEPTH_TEST);
  }
  gl_.BindVertexArray(0);
  gl_.UseProgram(0);
}

std::vector<std::uint8_t> TerrainView::read_pixels(int width, int height) const {
  std::vector<std::uint8_t> rows(static_cast<std::size_t>(width) * height * 3);
  gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl_.ReadBuffer(GL_BACK);
  gl_.ReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  std::vector<std::uint8_t> flipped(rows.size());
  const std::size_t stride = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height; ++y)
    std::copy_n(rows.data() + static_cast<std::size_t>(height - 1 - y) * stride, stride,
                flipped.data() + static_cast<std::size_t>(y) * stride);
  return flipped;
}

}  // namespace sb
