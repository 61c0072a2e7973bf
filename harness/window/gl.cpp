#include "harness/window/gl.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <stdexcept>
#include <string>

namespace sb::gl {

Api load() {
  Api api;
#define SB_GL_LOAD(type, name)                                       \
  api.name = reinterpret_cast<type>(glfwGetProcAddress("gl" #name)); \
  if (!api.name) throw std::runtime_error("OpenGL: no entry point gl" #name " (need OpenGL 3.3)");
  SB_GL_FUNCTIONS(SB_GL_LOAD)
#undef SB_GL_LOAD
  return api;
}

}  // namespace sb::gl
