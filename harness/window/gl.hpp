#pragma once
// OpenGL 3.3 core entry points for the interactive window, taken from GLFW's
// glfwGetProcAddress once the window's context is current. (The process also links OSMesa,
// which exports the plain gl* symbols for the offscreen renderer; calling through these
// pointers keeps the window on the window's GL.)
#include <GL/glcorearb.h>

namespace sb::gl {

#define SB_GL_FUNCTIONS(X)                                     \
  X(PFNGLCLEARCOLORPROC, ClearColor)                           \
  X(PFNGLCLEARPROC, Clear)                                     \
  X(PFNGLVIEWPORTPROC, Viewport)                               \
  X(PFNGLENABLEPROC, Enable)                                   \
  X(PFNGLDISABLEPROC, Disable)                                 \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                             \
  X(PFNGLPOLYGONMODEPROC, PolygonMode)                         \
  X(PFNGLPOLYGONOFFSETPROC, PolygonOffset)                     \
  X(PFNGLREADPIXELSPROC, ReadPixels)                           \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                           \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                         \
  X(PFNGLFINISHPROC, Finish)                                   \
  X(PFNGLGETSTRINGPROC, GetString)                             \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                 \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                 \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)           \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                           \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                           \
  X(PFNGLBUFFERDATAPROC, BufferData)                           \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                     \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray) \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)         \
  X(PFNGLCREATESHADERPROC, CreateShader)                       \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                       \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                     \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                         \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)               \
  X(PFNGLDELETESHADERPROC, DeleteShader)                       \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                     \
  X(PFNGLATTACHSHADERPROC, AttachShader)                       \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                         \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                       \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)             \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                     \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                           \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)           \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv)               \
  X(PFNGLUNIFORM4FPROC, Uniform4f)                             \
  X(PFNGLUNIFORM3FPROC, Uniform3f)                             \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                             \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                             \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                           \
  X(PFNGLDRAWELEMENTSPROC, DrawElements)

struct Api {
#define SB_GL_MEMBER(type, name) type name = nullptr;
  SB_GL_FUNCTIONS(SB_GL_MEMBER)
#undef SB_GL_MEMBER
};

// Loads every entry point through glfwGetProcAddress (a context must be current). Throws
// std::runtime_error naming the first one missing.
Api load();

}  // namespace sb::gl
