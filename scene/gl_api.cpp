#include "gl_api.h"

#include <EGL/egl.h>

#include <stdexcept>

namespace viper {
namespace scene {

GlApi loadGlApi(GlLoader loader) {
  GlApi gl;
  if (loader == GlLoader::kDirect) {
#define VIPER_SCENE_GL_DIRECT(name) gl.name = &::gl##name;
    VIPER_SCENE_GL_FUNCTIONS(VIPER_SCENE_GL_DIRECT)
#undef VIPER_SCENE_GL_DIRECT
    return gl;
  }
#define VIPER_SCENE_GL_PROC(name)                                                         \
  gl.name = reinterpret_cast<decltype(gl.name)>(eglGetProcAddress("gl" #name));           \
  if (!gl.name) throw std::runtime_error("eglGetProcAddress found no gl" #name);
  VIPER_SCENE_GL_FUNCTIONS(VIPER_SCENE_GL_PROC)
#undef VIPER_SCENE_GL_PROC
  return gl;
}

std::string glLoaderName(GlLoader loader) { return loader == GlLoader::kDirect ? "direct" : "egl-proc"; }

}  // namespace scene
}  // namespace viper
