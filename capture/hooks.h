// Lookup of the interceptor's own exported entry points by name, for eglGetProcAddress,
// glXGetProcAddress and dlsym.
#pragma once

namespace viper {
namespace capture {

/// The interceptor's function for a GL, EGL or GLX name, or null if it does not wrap that name.
void* wrapperFor(const char* name);

}  // namespace capture
}  // namespace viper
