// Lookup of the interceptor's own exported entry points by name, for eglGetProcAddress,
// glXGetProcAddress and dlsym.
#pragma once

#include <cstddef>
#include <cstring>

namespace viper {
namespace capture {

/// On the functions that run when the sanitizer runtime itself looks up the functions it intercepts
/// (dlsym(RTLD_NEXT, ...) from libasan's or libtsan's initialisation, before its shadow memory and
/// its thread state exist): no instrumentation there in the sanitized builds of the layer
/// (viper_intercept_asan, scripts/sanitize.sh asan and tsan). Under ThreadSanitizer even a
/// function's entry is instrumented (__tsan_func_entry, which crashes before the runtime is up), so
/// "thread" is needed as well. These functions also call nothing a runtime intercepts (string
/// functions, dlopen, a guarded static's __cxa_guard_acquire): the interceptor is not ready yet.
#define VIPER_NO_SANITIZE __attribute__((no_sanitize("address", "undefined", "thread")))

/// An exported wrapper of a GL, EGL or GLX function (the program's calls resolve to it).
#define VIPER_EXPORT extern "C" __attribute__((visibility("default")))

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
