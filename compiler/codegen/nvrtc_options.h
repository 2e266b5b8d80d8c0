// The NVRTC options of a generated config source, one definition for every loader that compiles one (the C++
// API, kage.jax, kagec bench --gpu): they are part of the kernel cache's key, so kernels compiled ahead by one
// are found by the others. Included by CUDA builds only (NvrtcOptions comes with the CUDA backend).
#pragma once

#include <string>

#include "compiler/codegen/build.h"
#include "compiler/codegen/codegen.h"
#include "runtime/cuda/module_loader.h"

namespace kage {

/// The runtime headers the generated source includes, and the generator's version.
inline NvrtcOptions generated_source_options() {
  NvrtcOptions options;
  options.include_dir = runtime_include_dir();
  options.generator_version = std::to_string(kCodegenVersion);
  return options;
}

}  // namespace kage
