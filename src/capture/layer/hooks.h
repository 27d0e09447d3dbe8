// Lookup of the interceptor's own exported entry points by name, for eglGetProcAddress,
// glXGetProcAddress and dlsym.
#pragma once

#include <cstddef>
#include <cstring>

namespace viper {
namespace capture {

/// On the functions that run when the sanitizer runtime itself looks up the functions it intercepts
/// (dlsym(RTLD_NEXT, ...) from libasan's initialisation, before its shadow memory exists): no
/// instrumentation there in the sanitized build of the layer (viper_intercept_asan).
#define VIPER_NO_SANITIZE __attribute__((no_sanitize("address", "undefined")))

/// One exported wrapper: its name and address.
struct HookEntry {
  const char* name;
  void* fn;
};
#define VIPER_HOOK_ENTRY(f) ::viper::capture::HookEntry{#f, reinterpret_cast<void*>(&::f)}

/// The wrapper named `name` in `entries`, or null.
template <size_t N>
VIPER_NO_SANITIZE void* findHook(const HookEntry (&entries)[N], const char* name) {
  for (const HookEntry& e : entries)
    if (std::strcmp(e.name, name) == 0) return e.fn;
  return nullptr;
}

/// The interceptor's function for a GL, EGL or GLX name, or null if it does not wrap that name.
VIPER_NO_SANITIZE void* wrapperFor(const char* name);

}  // namespace capture
}  // namespace viper
