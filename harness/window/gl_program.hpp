#pragma once
// The window's shader programs: compiling and linking (errors thrown with the driver's log),
// and the terrain's fragment shader, which the mesh and the lattice draws share so that both
// look the same (facet normals, height colours, the renderer's light).
namespace sb {

// A linked program from vertex and fragment shader sources; throws std::runtime_error.
unsigned link_program(const char* vertex_source, const char* fragment_source);

// Inputs: `world` (position minus the view's origin); uniforms z_range, tint (alpha > 0: a
// flat colour, for the wireframe), light, ambient_diffuse.
extern const char* const kSurfaceFragmentShader;

}  // namespace sb
