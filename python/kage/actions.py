"""Hands a step's actions to the runtime without a copy where the runtime can read them in place.

Accepted: numpy arrays and sequences of ints (host); anything with ``__dlpack__`` (torch, JAX, CuPy,
numpy ...), read in place when it lives on the GPU and the environment does too; anything with
``__cuda_array_interface__`` (Numba, CuPy, torch). Shape ``(num_envs,)``, an integer dtype; on the GPU
int32 or int64. The runtime checks the values: host actions before the step (``ValueError``), device
actions in the step kernel, where an out-of-range value raises ``ValueError`` at a later call (checking at
once would wait for the GPU). This module checks only what the binding needs: shape, dtype and device.
"""
import numpy as np

from kage._native import native

_DLPACK_CPU, _DLPACK_CUDA, _DLPACK_CUDA_HOST, _DLPACK_CUDA_MANAGED = 1, 2, 3, 13


def submit(handle, actions) -> None:
    """Steps ``handle`` with ``actions``; raises ValueError for a wrong shape, dtype, device or value."""
    n = handle.num_envs
    actions = _unmasked(actions)
    if hasattr(actions, "__dlpack_device__"):
        device_type, _ = actions.__dlpack_device__()
        if device_type in (_DLPACK_CUDA, _DLPACK_CUDA_MANAGED):
            _require_cuda_env(handle, actions)
            _check_shape(getattr(actions, "shape", None), n)
            # The producer orders its pending work before our stream (DLPack protocol, 1 = legacy default).
            stream = handle.stream or 1
            handle.step_dlpack(actions.__dlpack__(stream=stream))
            return
        if device_type in (_DLPACK_CPU, _DLPACK_CUDA_HOST):
            _step_host(handle, _host_array(actions), n)
            return
        raise ValueError(f"actions on DLPack device type {device_type}: pass them in host or CUDA memory")
    if hasattr(actions, "__cuda_array_interface__"):
        _require_cuda_env(handle, actions)
        _step_cuda_array_interface(handle, actions.__cuda_array_interface__, n)
        return
    _step_host(handle, np.asarray(actions), n)


def _unmasked(actions):
    """A masked array's data, refused where any element is masked (the binding would read the hidden values)."""
    if isinstance(actions, np.ma.MaskedArray):
        if np.ma.getmaskarray(actions).any():
            raise ValueError("actions: a masked array with masked elements: fill them (actions.filled(value)) or "
                             "pass a plain array")
        return actions.data
    return actions


def _host_array(actions) -> np.ndarray:
    if isinstance(actions, np.ndarray):
        return actions
    try:
        return np.from_dlpack(actions)
    except (BufferError, RuntimeError, TypeError) as e:
        raise ValueError(f"actions could not be read through DLPack ({e}); pass a numpy array") from e


def _require_cuda_env(handle, actions) -> None:
    if handle.device != "cuda":
        raise ValueError(
            f"actions are in GPU memory ({type(actions).__name__}) but the environment runs on the CPU: "
            "pass host actions (e.g. actions.cpu()) or make the environment with device='cuda'"
        )


def _check_shape(shape, n: int) -> None:
    if shape is not None and tuple(shape) != (n,):
        raise ValueError(f"actions of shape {tuple(shape)}, expected ({n},): one action per environment")


def _step_host(handle, a: np.ndarray, n: int) -> None:
    _check_shape(a.shape, n)
    handle.step_host(_native_integers(a))


def _native_integers(a: np.ndarray, copy_strided: bool = False) -> np.ndarray:
    if a.dtype.kind not in "iu":
        raise ValueError(f"actions of dtype {a.dtype}, expected an integer dtype (int32 or int64): "
                         f"{native().action_range_text()}")
    if a.dtype not in (np.int32, np.int64) or not a.flags.aligned or (
            copy_strided and any(s % a.dtype.itemsize for s in a.strides)):
        # A native, aligned int64 copy: the binding reads only native int32/int64 whose byte stride is a
        # multiple of the item size, so a field of a packed structured array, another byte order or a
        # misaligned buffer is copied here. int64 holds every other integer kind's values (uint64 above 2**63
        # would turn negative: refused here, with their value), so the runtime's range check sees them unchanged.
        if a.dtype.kind == "u" and a.size and a.max() > np.iinfo(np.int64).max:
            at = tuple(int(i) for i in np.argwhere(a > np.iinfo(np.int64).max)[0])
            where = f"batch {at[0]} (none stepped): " if len(at) == 2 else ""
            raise ValueError(f"kage: {where}action {int(a[at])} for environment {at[-1]}: "
                             f"{native().action_range_text()}")
        a = a.astype(np.int64)
    return a


def submit_rows(handles, actions) -> None:
    """Steps handles[i] with actions[i] for every i in one call, the runtime looping over the batches (each of
    num_envs environments): ``actions`` [len(handles), num_envs], host or GPU, as ``submit`` takes one row.
    GPU actions are ordered for the first batch's stream; the runtime orders the others' after it."""
    shape = (len(handles), handles[0].num_envs)
    actions = _unmasked(actions)
    if hasattr(actions, "__dlpack_device__"):
        device_type, _ = actions.__dlpack_device__()
        if device_type in (_DLPACK_CUDA, _DLPACK_CUDA_MANAGED):
            _check_rows(getattr(actions, "shape", None), shape)
            native().step_rows(handles, actions.__dlpack__(stream=handles[0].stream or 1))
            return
        if device_type not in (_DLPACK_CPU, _DLPACK_CUDA_HOST):
            raise ValueError(f"actions on DLPack device type {device_type}: pass them in host or CUDA memory")
        actions = _host_array(actions)
    a = np.asarray(actions)
    _check_rows(a.shape, shape)
    native().step_rows(handles, _native_integers(a, copy_strided=True))


def _check_rows(shape, expected) -> None:
    if shape is None or tuple(shape) != expected:
        raise ValueError(f"actions of shape {None if shape is None else tuple(shape)}, expected {expected}: a row of "
                         "one action per environment for each batch")


def _step_cuda_array_interface(handle, cai: dict, n: int) -> None:
    _check_shape(cai["shape"], n)
    typestr = cai["typestr"]
    if typestr not in ("<i4", "<i8"):
        raise ValueError(f"actions of type {typestr}, expected int32 (<i4) or int64 (<i8) on the GPU")
    itemsize = int(typestr[-1])
    strides = cai.get("strides")
    if strides is not None and strides[0] % itemsize:
        raise ValueError(f"actions: a byte stride {strides[0]} is not a multiple of the item size {itemsize}: pass a "
                         "contiguous copy")
    if cai.get("mask") is not None:
        raise ValueError("actions: a masked __cuda_array_interface__ array: pass one without a mask")
    stride = 1 if strides is None else strides[0] // itemsize
    ptr, _ = cai["data"]
    stream = cai.get("stream")
    handle.step_device(ptr, itemsize == 8, stride, -1 if stream is None else stream)
