#include "harness/window/gl_driver.hpp"

#include <dlfcn.h>
#include <link.h>

#include <string_view>

namespace sb {

namespace {

bool is_gl_driver(std::string_view path) {
  const std::string_view file = path.substr(path.rfind('/') + 1);
  return file.find("_dri.so") != std::string_view::npos || file.starts_with("libgallium") ||
         file.starts_with("libGLX_") || file.starts_with("libEGL_");
}

}  // namespace

int keep_gl_driver_loaded() {
  int pinned = 0;
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void* count) {
        if (info->dlpi_name && is_gl_driver(info->dlpi_name)) {
          // A second reference that is never closed, with the object now undeletable.
          if (dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE)) ++*static_cast<int*>(count);
        }
        return 0;
      },
      &pinned);
  return pinned;
}

}  // namespace sb
