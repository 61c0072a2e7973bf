#include "harness/window/gl_program.hpp"

#include <epoxy/gl.h>

#include <stdexcept>
#include <string>

namespace sb {

namespace {

unsigned compile(GLenum type, const char* source) {
  const unsigned s = glCreateShader(type);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    glDeleteShader(s);
    throw std::runtime_error(std::string("OpenGL shader: ") + log);
  }
  return s;
}

}  // namespace

// Facet normals from screen-space derivatives: every triangle shows as it is.
const char* const kSurfaceFragmentShader = R"(#version 330 core
in vec3 world;
uniform vec2 z_range;
uniform vec4 tint;
uniform vec3 light;  // the renderer's light and weights (render/camera.hpp)
uniform vec2 ambient_diffuse;
out vec4 colour;
void main() {
  if (tint.a > 0.0) { colour = tint; return; }
  vec3 n = normalize(cross(dFdx(world), dFdy(world)));
  if (n.z < 0.0) n = -n;
  float h = clamp((world.z - z_range.x) / max(z_range.y - z_range.x, 1e-6), 0.0, 1.0);
  vec3 low = vec3(0.55, 0.42, 0.26), high = vec3(0.93, 0.82, 0.60);
  vec3 base = mix(low, high, h);
  float diffuse = max(dot(n, light), 0.0);
  colour = vec4(base * (ambient_diffuse.x + ambient_diffuse.y * diffuse), 1.0);
})";

unsigned link_program(const char* vertex_source, const char* fragment_source) {
  const unsigned v = compile(GL_VERTEX_SHADER, vertex_source), f = compile(GL_FRAGMENT_SHADER, fragment_source);
  const unsigned p = glCreateProgram();
  glAttachShader(p, v);
  glAttachShader(p, f);
  glLinkProgram(p);
  glDeleteShader(v);
  glDeleteShader(f);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    glDeleteProgram(p);
    throw std::runtime_error(std::string("OpenGL program: ") + log);
  }
  return p;
}

}  // namespace sb
