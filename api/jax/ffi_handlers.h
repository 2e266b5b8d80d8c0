// kage.jax's XLA FFI handlers (typed FFI, xla/ffi/api/ffi.h): kage_reset and kage_step, each an
// instantiate stage that finds the config by its "spec_hash" attribute and an execute stage. The CPU
// handlers run the CPU batch code (cpu_handlers.cpp); the CUDA handlers launch the specialised kernels on
// XLA's stream (cuda_handlers.cpp, built with the CUDA backend). jax_module.cpp hands them to JAX.
#pragma once

#include "xla/ffi/api/c_api.h"

namespace kage::jax {

/// The stages of one FFI target, as jax.ffi.register_ffi_target takes them.
struct HandlerBundle {
  XLA_FFI_Handler* instantiate;
  XLA_FFI_Handler* execute;
};

/// A state type of the instantiate stage, as jax.ffi.register_ffi_type takes it.
struct StateType {
  XLA_FFI_TypeId* type_id;
  const XLA_FFI_TypeInfo* type_info;
};

HandlerBundle cpu_reset_handler();
HandlerBundle cpu_step_handler();
StateType cpu_instance_type();

#if defined(KAGE_JAX_HAVE_CUDA)
HandlerBundle cuda_reset_handler();
HandlerBundle cuda_step_handler();
StateType cuda_instance_type();
#endif

}  // namespace kage::jax
