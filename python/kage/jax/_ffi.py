"""The two XLA FFI calls of kage.jax, ``kage_reset`` and ``kage_step`` (typed FFI, handlers in
``kage._kage_jax``; buffer order in api/jax/ffi_buffers.h), registered with JAX once per process.

``vmap_method="broadcast_all"``: under ``jax.vmap`` an unbatched operand is broadcast to the batch and the
handler gets one call with leading batch axes, which it flattens into the environment axis (every
environment is independent). One launch for all batches, and the same results as separate calls.
"""
import jax

from kage.jax import _native
from kage.vector import INFO_FIELDS

#: Step arguments 1-4 (latent, segments, visual, final_obs) update results 0-3 in place, and the
#: final_info arguments the final_info results.
_FINAL_INFO_ARG, _FINAL_INFO_RET = 6, 12
STEP_ALIASES = {**{1 + i: i for i in range(4)},
                **{_FINAL_INFO_ARG + i: _FINAL_INFO_RET + i for i in range(len(INFO_FIELDS))}}

_registered = False


def register() -> None:
    """Registers the handlers and their state types with JAX for every platform the extension has."""
    global _registered
    if _registered:
        return
    module = _native.module()
    # With the backends up, each registration applies at once: registered before, JAX would hand XLA the
    # targets before the state types they use, which XLA refuses.
    jax.devices()
    for platform, (name, registration) in module.state_types().items():
        jax.ffi.register_ffi_type(name, registration, platform=platform)
    for platform, targets in module.targets().items():
        for target, stages in targets.items():
            jax.ffi.register_ffi_target(target, stages, platform=platform)
    _registered = True


def reset_call(result_shapes):
    return jax.ffi.ffi_call("kage_reset", result_shapes, vmap_method="broadcast_all")


def step_call(result_shapes):
    return jax.ffi.ffi_call("kage_step", result_shapes, vmap_method="broadcast_all",
                            input_output_aliases=STEP_ALIASES)
