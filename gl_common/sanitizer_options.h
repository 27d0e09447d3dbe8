// Included by the main file of each of our OpenGL programs (exactly one translation unit each). In a
// sanitizer build (scripts/sanitize.sh), LeakSanitizer would report Mesa's own allocations at exit:
// its driver is unloaded before the leak check runs, so they cannot even be named, let alone
// suppressed by library. The programs therefore run without leak detection; every other check of
// AddressSanitizer and UndefinedBehaviorSanitizer stays on. Nothing changes in a normal build.
#pragma once

#if defined(__SANITIZE_ADDRESS__)
extern "C" const char* __asan_default_options() { return "detect_leaks=0"; }
#endif
