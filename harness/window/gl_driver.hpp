#pragma once
// The OpenGL driver's shared objects, kept loaded until the process exits.
namespace sb {

// Marks every loaded object of the GL driver (Mesa's *_dri.so and libgallium, libglvnd's
// vendor libraries libGLX_* and libEGL_*) RTLD_NODELETE, so that closing the window and GLFW
// does not unload it. Call once the window's context is current (the driver is loaded then).
// Why: the driver keeps process-lifetime allocations referenced from its own globals; unloaded
// (dlclose at glfwTerminate), those references vanish before LeakSanitizer scans at exit and it
// reports them as leaks of "<unknown module>", which no suppression can name. Loaded, they are
// reachable, as they are for the driver. Objects are found by path (dl_iterate_phdr), pinned
// with dlopen(RTLD_NOLOAD | RTLD_NODELETE), which loads nothing new. Returns how many.
int keep_gl_driver_loaded();

}  // namespace sb
