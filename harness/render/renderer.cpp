#include "harness/render/renderer.hpp"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "harness/render/camera.hpp"
#include "harness/render/colour.hpp"
#include "harness/render/mesh.hpp"

namespace sb {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kViewBearingDeg = 160.0;  // camera position, clockwise from north (+y)
constexpr double kViewElevationDeg = 40.0;
constexpr double kFovYDeg = 30.0;
constexpr double kMaxPixels = 48e6;  // drawn pixels (supersampled); larger pictures get less supersampling
constexpr float kBackground[3] = {0.93f, 0.93f, 0.92f};
constexpr float kSand[3] = {0.86f, 0.74f, 0.53f};
constexpr float kSkirt[3] = {0.60f, 0.50f, 0.36f};
constexpr double kSkirtAmbient = 0.6;  // the walls face away from the light on two sides
constexpr float kEdge[4] = {0.22f, 0.16f, 0.10f, 0.55f};
constexpr float kConstrained[4] = {0.86f, 0.07f, 0.07f, 1.0f};

constexpr const char* kSurfaceVs = R"(#version 120
attribute vec3 a_position;
attribute vec3 a_normal;
uniform mat4 u_mvp;
varying vec3 v_normal;
varying float v_z;
void main() {
  v_normal = a_normal;
  v_z = a_position.z;
  gl_Position = u_mvp * vec4(a_position, 1.0);
}
)";

// Lambert shading with an ambient term; in contour mode the albedo comes from the height
// colour map and lines are drawn where z crosses (k + 1/2) * u_step: half a step off the
// round heights that level sand usually sits on, whose "contour" would only trace the
// mesh around every disturbance. Where the surface is level within a pixel, no line.
constexpr const char* kSurfaceFs = R"(#version 120
varying vec3 v_normal;
varying float v_z;
uniform vec3 u_light;
uniform vec3 u_albedo;
uniform float u_ambient;
uniform float u_diffuse;
uniform int u_contours;
uniform float u_z0;
uniform float u_zspan;
uniform float u_zero;
uniform float u_step;
uniform float u_line_px;
uniform sampler1D u_cmap;
void main() {
  vec3 n = normalize(v_normal);
  float shade = u_ambient + u_diffuse * max(dot(n, u_light), 0.0);
  vec3 albedo = u_albedo;
  if (u_contours == 1) albedo = texture1D(u_cmap, clamp((v_z - u_z0) / u_zspan, 0.0, 1.0)).rgb;
  vec3 c = albedo * shade;
  if (u_contours == 1) {
    float f = (v_z - u_zero) / u_step - 0.5;
    float w = fwidth(f);
    if (w > 1e-3) {
      float d = abs(f - floor(f + 0.5)) / w;
      float half_w = 0.5 * u_line_px;
      float line = 1.0 - smoothstep(half_w - 0.5, half_w + 0.5, d);
      c = mix(c, vec3(0.12, 0.09, 0.06), 0.85 * line);
    }
  }
  gl_FragColor = vec4(c, 1.0);
}
)";

constexpr const char* kLineVs = R"(#version 120
attribute vec3 a_position;
uniform mat4 u_mvp;
void main() { gl_Position = u_mvp * vec4(a_position, 1.0); }
)";

constexpr const char* kLineFs = R"(#version 120
uniform vec4 u_colour;
void main() { gl_FragColor = u_colour; }
)";

GLuint compile(GLenum type, const char* source) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("renderer: shader does not compile: ") + log);
  }
  return s;
}

GLuint link(const char* vs, const char* fs) {
  const GLuint p = glCreateProgram();
  const GLuint v = compile(GL_VERTEX_SHADER, vs), f = compile(GL_FRAGMENT_SHADER, fs);
  glAttachShader(p, v);
  glAttachShader(p, f);
  glBindAttribLocation(p, 0, "a_position");
  glBindAttribLocation(p, 1, "a_normal");
  glLinkProgram(p);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    throw std::runtime_error(std::string("renderer: shaders do not link: ") + log);
  }
  return p;
}

// The camera for a frame, in coordinates relative to `c`. It depends on the frame alone, so
// every back-end drawn with one frame is seen from one place.
Mat4 camera(const RenderFrame& frame, const Vec3& c, View view, double aspect) {
  const Vec2 lo = frame.region.lo - c.head<2>(), hi = frame.region.hi - c.head<2>();
  const double z_lo = frame.z_min_m - c.z(), z_hi = frame.z_max_m - c.z();
  // Depth room for everything outside the region: the domain, hills up to a metre, skirts.
  const double reach = (frame.domain.hi - frame.domain.lo).norm() + (z_hi - z_lo) + std::abs(c.z()) + 1.0;
  if (view == View::Top) {
    const Vec2 mid = (lo + hi) / 2.0, half = (hi - lo) / 2.0;
    double hw = half.x(), hh = half.y();
    if (hw < hh * aspect)
      hw = hh * aspect;
    else
      hh = hw / aspect;
    const double eye_z = z_hi + reach;
    Mat4 view_m = Mat4::Identity();
    view_m(0, 3) = -mid.x();
    view_m(1, 3) = -mid.y();
    view_m(2, 3) = -eye_z;
    return ortho(-hw, hw, -hh, hh, 0.0, eye_z + reach) * view_m;
  }
  const double b = kViewBearingDeg * kDeg, e = kViewElevationDeg * kDeg;
  const Vec3 to_eye(std::sin(b) * std::cos(e), std::cos(b) * std::cos(e), std::sin(e));
  const Vec3 right = (-to_eye).cross(Vec3::UnitZ()).normalized();
  const Vec3 up = right.cross(-to_eye);
  // The box to fit: the region between the lowest and highest heights, plus the skirt
  // walls down to z = 0 on the sides where the region reaches the domain's edge.
  const Vec2 dlo = frame.domain.lo - c.head<2>(), dhi = frame.domain.hi - c.head<2>();
  const double tol = 1e-9 * (1.0 + (dhi - dlo).norm());
  std::vector<Vec3> points;  // (right, up, towards the eye) coordinates
  for (double x : {lo.x(), hi.x()})
    for (double y : {lo.y(), hi.y()}) {
      const bool edge = std::abs(x - dlo.x()) < tol || std::abs(x - dhi.x()) < tol || std::abs(y - dlo.y()) < tol ||
                        std::abs(y - dhi.y()) < tol;
      for (double z : {z_lo, z_hi, edge ? -c.z() : z_lo}) {
        const Vec3 p(x, y, z);
        points.emplace_back(p.dot(right), p.dot(up), p.dot(to_eye));
      }
    }
  // The nearest eye, looking along -to_eye, whose frustum holds every point, centred: for a
  // distance d the sideways offset a must satisfy |x - a| <= tan * (d - depth) for all points.
  const double tan_y = 0.94 * std::tan(kFovYDeg * kDeg / 2.0), tan_x = tan_y * aspect;
  auto offset = [&](double d, int axis, double tan, double& centre) {
    double a_lo = -std::numeric_limits<double>::infinity(), a_hi = -a_lo;
    for (const Vec3& p : points) {
      a_lo = std::max(a_lo, p[axis] - tan * (d - p.z()));
      a_hi = std::min(a_hi, p[axis] + tan * (d - p.z()));
    }
    centre = (a_lo + a_hi) / 2.0;
    return a_lo <= a_hi;
  };
  double near_d = -std::numeric_limits<double>::infinity(), far_d = 1e-3;
  for (const Vec3& p : points) {
    near_d = std::max(near_d, p.z());
    far_d = std::max({far_d, p.z() + std::abs(p.x()) / tan_x, p.z() + std::abs(p.y()) / tan_y});
  }
  double ax = 0.0, ay = 0.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = (near_d + far_d) / 2.0;
    if (offset(mid, 0, tan_x, ax) && offset(mid, 1, tan_y, ay))
      far_d = mid;
    else
      near_d = mid;
  }
  offset(far_d, 0, tan_x, ax);
  offset(far_d, 1, tan_y, ay);
  const double distance = far_d;
  const Vec3 eye = right * ax + up * ay + to_eye * distance;
  return perspective(kFovYDeg * kDeg, aspect, 0.05 * distance, distance + reach) *
         look_at(eye, eye - to_eye, Vec3::UnitZ());
}

struct Buffer {
  GLuint id = 0;
  Buffer(GLenum target, const void* data, std::size_t bytes) {
    glGenBuffers(1, &id);
    glBindBuffer(target, id);
    glBufferData(target, static_cast<GLsizeiptr>(bytes), bytes ? data : nullptr, GL_STATIC_DRAW);
  }
  ~Buffer() { glDeleteBuffers(1, &id); }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
};

void attribute(GLuint location, const Buffer& b) {
  glBindBuffer(GL_ARRAY_BUFFER, b.id);
  glEnableVertexAttribArray(location);
  glVertexAttribPointer(location, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
}
}  // namespace

}  // namespace sb

// OSMesa keeps a framebuffer for every buffer size it has drawn into until the process ends
// (a few hundred bytes, never freed by Mesa); LeakSanitizer, in the sanitizer builds, is told
// that those are Mesa's, so that leaks of our own still fail.
extern "C" const char* __lsan_default_suppressions() { return "leak:libOSMesa.so\n"; }

namespace sb {

struct Renderer::Gl {
  OSMesaContext context = nullptr;
  std::vector<std::uint8_t> buffer;
  GLuint surface = 0, line = 0, cmap = 0;
  int max_size = 1;
  ~Gl() {
    if (!context) return;
    if (OSMesaGetCurrentContext() == context) {
      glDeleteProgram(surface);
      glDeleteProgram(line);
      glDeleteTextures(1, &cmap);
      OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);  // releases the framebuffer Mesa made for us
    }
    OSMesaDestroyContext(context);
  }
};

Renderer::Renderer() : gl_(std::make_unique<Gl>()) {
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         24,
                         OSMESA_STENCIL_BITS,
                         0,
                         OSMESA_ACCUM_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_COMPAT_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         2,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         1,
                         0};
  gl_->context = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!gl_->context) throw std::runtime_error("renderer: OSMesa cannot create an OpenGL 2.1 context");
  // Shaders, the colour map and the size limit need a current context: a 1 x 1 buffer.
  gl_->buffer.assign(4, 0);
  if (!OSMesaMakeCurrent(gl_->context, gl_->buffer.data(), GL_UNSIGNED_BYTE, 1, 1))
    throw std::runtime_error("renderer: OSMesa cannot make its context current");
  GLint max_w = 0, max_h = 0;
  OSMesaGetIntegerv(OSMESA_MAX_WIDTH, &max_w);
  OSMesaGetIntegerv(OSMESA_MAX_HEIGHT, &max_h);
  GLint dims[2] = {0, 0};
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, dims);
  gl_->max_size = std::max(1, std::min({max_w, max_h, dims[0], dims[1]}));
  gl_->surface = link(kSurfaceVs, kSurfaceFs);
  gl_->line = link(kLineVs, kLineFs);
  std::vector<std::uint8_t> ramp(256 * 3);
  for (int i = 0; i < 256; ++i) {
    const Rgb c = to_rgb(height_colour(i / 255.0));
    ramp[3 * i] = c.r, ramp[3 * i + 1] = c.g, ramp[3 * i + 2] = c.b;
  }
  glGenTextures(1, &gl_->cmap);
  glBindTexture(GL_TEXTURE_1D, gl_->cmap);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage1D(GL_TEXTURE_1D, 0, GL_RGB8, 256, 0, GL_RGB, GL_UNSIGNED_BYTE, ramp.data());
  glTexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_1D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
}

Renderer::~Renderer() = default;

int Renderer::max_size() const { return gl_->max_size; }

Image Renderer::render(const SurfaceMesh& mesh, const RenderFrame& frame, const RenderOptions& o) {
  if (o.width < 1 || o.height < 1 || o.width > gl_->max_size || o.height > gl_->max_size)
    throw std::invalid_argument("renderer: image size " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                                " is outside 1.." + std::to_string(gl_->max_size));
  int ss = std::max(1, o.supersample);
  auto too_big = [&](int f) {
    return o.width * f > gl_->max_size || o.height * f > gl_->max_size ||
           static_cast<double>(o.width) * o.height * f * f > kMaxPixels;
  };
  while (ss > 1 && too_big(ss)) --ss;
  const int w = o.width * ss, h = o.height * ss;
  gl_->buffer.assign(static_cast<std::size_t>(w) * h * 4, 0);
  if (!OSMesaMakeCurrent(gl_->context, gl_->buffer.data(), GL_UNSIGNED_BYTE, w, h))
    throw std::runtime_error("renderer: OSMesa cannot use a " + std::to_string(w) + "x" + std::to_string(h) +
                             " buffer");

  const Vec2 mid = (frame.region.lo + frame.region.hi) / 2.0;
  const RenderMesh rm =
      prepare_render_mesh(mesh, Vec3(mid.x(), mid.y(), (frame.z_min_m + frame.z_max_m) / 2.0), o.wireframe);
  const Eigen::Matrix4f mvp = camera(frame, rm.centre, o.view, static_cast<double>(o.width) / o.height).cast<float>();

  glViewport(0, 0, w, h);
  glClearColor(kBackground[0], kBackground[1], kBackground[2], 1.0f);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  if (o.wireframe) {
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 2.0f);
  } else {
    glDisable(GL_POLYGON_OFFSET_FILL);
  }

  // Surface, then the skirt walls under its boundary.
  const Vec3 light = light_direction();
  glUseProgram(gl_->surface);
  auto loc = [&](const char* name) { return glGetUniformLocation(gl_->surface, name); };
  glUniformMatrix4fv(loc("u_mvp"), 1, GL_FALSE, mvp.data());
  glUniform3f(loc("u_light"), static_cast<float>(light.x()), static_cast<float>(light.y()),
              static_cast<float>(light.z()));
  glUniform1f(loc("u_ambient"), static_cast<float>(kAmbient));
  glUniform1f(loc("u_diffuse"), static_cast<float>(kDiffuse));
  glUniform1f(loc("u_z0"), static_cast<float>(frame.z_min_m - rm.centre.z()));
  glUniform1f(loc("u_zspan"), static_cast<float>(std::max(frame.z_max_m - frame.z_min_m, 1e-9)));
  glUniform1f(loc("u_zero"), static_cast<float>(-rm.centre.z()));
  glUniform1f(loc("u_step"), static_cast<float>(frame.contour_step_m > 0.0 ? frame.contour_step_m : 1.0));
  glUniform1f(loc("u_line_px"), static_cast<float>(1.2 * ss));
  glUniform1i(loc("u_cmap"), 0);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_1D, gl_->cmap);
  {
    const Buffer positions(GL_ARRAY_BUFFER, rm.positions.data(), rm.positions.size() * sizeof(float));
    const Buffer normals(GL_ARRAY_BUFFER, rm.normals.data(), rm.normals.size() * sizeof(float));
    const Buffer triangles(GL_ELEMENT_ARRAY_BUFFER, rm.triangles.data(), rm.triangles.size() * sizeof(std::uint32_t));
    glUniform3fv(loc("u_albedo"), 1, kSand);
    glUniform1i(loc("u_contours"), o.contours ? 1 : 0);
    attribute(0, positions);
    attribute(1, normals);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, triangles.id);
    if (!rm.triangles.empty())
      glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(rm.triangles.size()), GL_UNSIGNED_INT, nullptr);

    if (!rm.skirt_positions.empty()) {
      const Buffer skirt(GL_ARRAY_BUFFER, rm.skirt_positions.data(), rm.skirt_positions.size() * sizeof(float));
      const Buffer skirt_n(GL_ARRAY_BUFFER, rm.skirt_normals.data(), rm.skirt_normals.size() * sizeof(float));
      glUniform3fv(loc("u_albedo"), 1, kSkirt);
      glUniform1f(loc("u_ambient"), static_cast<float>(kSkirtAmbient));
      glUniform1i(loc("u_contours"), 0);
      attribute(0, skirt);
      attribute(1, skirt_n);
      glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(rm.skirt_positions.size() / 3));
    }
    glDisableVertexAttribArray(1);

    if (o.wireframe) {
      glUseProgram(gl_->line);
      glUniformMatrix4fv(glGetUniformLocation(gl_->line, "u_mvp"), 1, GL_FALSE, mvp.data());
      const GLint colour = glGetUniformLocation(gl_->line, "u_colour");
      glEnable(GL_BLEND);
      glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
      glDepthMask(GL_FALSE);
      attribute(0, positions);
      const Buffer edges(GL_ELEMENT_ARRAY_BUFFER, rm.edges.data(), rm.edges.size() * sizeof(std::uint32_t));
      glLineWidth(static_cast<float>(ss));
      glUniform4fv(colour, 1, kEdge);
      if (!rm.edges.empty()) glDrawElements(GL_LINES, static_cast<GLsizei>(rm.edges.size()), GL_UNSIGNED_INT, nullptr);
      const Buffer constrained(GL_ELEMENT_ARRAY_BUFFER, rm.constrained.data(),
                               rm.constrained.size() * sizeof(std::uint32_t));
      glLineWidth(static_cast<float>(1.5 * ss));
      glUniform4fv(colour, 1, kConstrained);
      if (!rm.constrained.empty())
        glDrawElements(GL_LINES, static_cast<GLsizei>(rm.constrained.size()), GL_UNSIGNED_INT, nullptr);
      glDisable(GL_BLEND);
      glDepthMask(GL_TRUE);
    }
    glDisableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
  }
  glFinish();
  if (const GLenum err = glGetError(); err != GL_NO_ERROR)
    throw std::runtime_error("renderer: OpenGL error " + std::to_string(err));

  // The OSMesa buffer is RGBA with row 0 at the bottom.
  Image big(w, h);
  auto& dst = big.bytes();
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* src = gl_->buffer.data() + static_cast<std::size_t>(h - 1 - y) * w * 4;
    std::uint8_t* out = dst.data() + static_cast<std::size_t>(y) * w * 3;
    for (int x = 0; x < w; ++x) {
      out[3 * x] = src[4 * x];
      out[3 * x + 1] = src[4 * x + 1];
      out[3 * x + 2] = src[4 * x + 2];
    }
  }
  return downsample(big, ss);
}

}  // namespace sb
