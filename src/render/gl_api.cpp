// libOSMesa loaded at the first picture (gl_api.h says why).
#include "render/gl_api.h"

#include <dlfcn.h>

namespace tailor::internal {
namespace {

struct LoadedApi {
  GlApi api;
  bool ok = false;
  std::string error;
};

LoadedApi load() {
  LoadedApi loaded;
  // Never closed: the library's own state lives until the process ends, as when it was linked.
  void* library = dlopen(TAILOR_OSMESA_SONAME, RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr) {
    const char* why = dlerror();
    loaded.error = std::string("cannot load ") + TAILOR_OSMESA_SONAME +
                   " (Mesa's off-screen OpenGL, Debian package libosmesa6): " + (why ? why : "not found");
    return loaded;
  }
#define TAILOR_GL_RESOLVE(name)                                                                          \
  loaded.api.name = reinterpret_cast<decltype(&::name)>(dlsym(library, #name));                          \
  if (loaded.api.name == nullptr) {                                                                      \
    loaded.error = std::string(TAILOR_OSMESA_SONAME) + " has no " #name ": a Mesa too old for previews"; \
    return loaded;                                                                                       \
  }
  TAILOR_GL_ENTRY_POINTS(TAILOR_GL_RESOLVE)
#undef TAILOR_GL_RESOLVE
  loaded.ok = true;
  return loaded;
}

const LoadedApi& loaded_api() {
  static const LoadedApi loaded = load();
  return loaded;
}

}  // namespace

bool load_gl_api(std::string& error) {
  const LoadedApi& loaded = loaded_api();
  if (!loaded.ok) error = loaded.error;
  return loaded.ok;
}

const GlApi& gl() { return loaded_api().api; }

}  // namespace tailor::internal
