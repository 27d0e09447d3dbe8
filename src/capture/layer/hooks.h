// Lookup of the interceptor's own exported entry points by name, for eglGetProcAddress,
// glXGetProcAddress and dlsym.
#pragma once

#include <cstddef>
#include <cstring>

namespace viper {
namespace capture {

/// One exported wrapper: its name and address.
struct HookEntry {
  const char* name;
  void* fn;
};
#define VIPER_HOOK_ENTRY(f) ::viper::capture::HookEntry{#f, reinterpret_cast<void*>(&::f)}

/// The wrapper named `name` in `entries`, or null.
template <size_t N>
void* findHook(const HookEntry (&entries)[N], const char* name) {
  for (const HookEntry& e : entries)
    if (std::strcmp(e.name, name) == 0) return e.fn;
  return nullptr;
}

/// The interceptor's function for a GL, EGL or GLX name, or null if it does not wrap that name.
void* wrapperFor(const char* name);

}  // namespace capture
}  // namespace viper
