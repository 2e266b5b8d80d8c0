// Compiler bugs (never the user's mistake): print and abort.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <string>

namespace kage {

[[noreturn]] inline void internal_error(const std::string& what, const char* file, int line) {
  std::fprintf(stderr, "kagec: internal error: %s (%s:%d); please report this\n", what.c_str(), file, line);
  std::abort();
}

}  // namespace kage

#define KAGE_INTERNAL_ASSERT(cond, what) \
  do {                                   \
    if (!(cond)) ::kage::internal_error((what), __FILE__, __LINE__); \
  } while (0)
