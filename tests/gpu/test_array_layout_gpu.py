"""Device actions of any layout the GPU batch can read are read as their values; a byte stride that is not a
multiple of the item size or a misaligned pointer is refused, naming the layout."""
import numpy as np
import pytest
import torch

import kage
from support import SIMPLEST

N = 6
ACTIONS = np.array([2, 6, 0, 7, 1, 4], dtype=np.int64)


class Interface:
    """A __cuda_array_interface__ over memory that `keep` owns."""

    def __init__(self, keep: torch.Tensor, ptr: int, typestr: str, strides):
        self.keep = keep
        self.__cuda_array_interface__ = {"shape": (N,), "typestr": typestr, "data": (ptr, False), "version": 3,
                                         "strides": strides, "stream": 1}


def state_after(actions) -> bytes:
    with kage.make_vec(SIMPLEST, N, device="cuda") as env:
        env.reset(seed=5)
        env.step(actions)
        return env.save_state()


@pytest.mark.parametrize("make", [
    lambda: torch.tensor(ACTIONS, device="cuda").repeat_interleave(3)[::3],
    lambda: torch.tensor(ACTIONS, device="cuda", dtype=torch.int32).repeat_interleave(2)[::2],
    lambda: torch.tensor(ACTIONS, device="cuda").flip(0).flip(0),
], ids=["dlpack-stride-3", "dlpack-i4-stride-2", "dlpack-flipped"])
def test_device_actions_of_any_readable_layout(make):
    assert state_after(make()) == state_after(ACTIONS)


def test_a_byte_stride_not_a_multiple_of_the_item_size_is_refused():
    raw = torch.zeros(9 * N, dtype=torch.uint8, device="cuda")
    with kage.make_vec(SIMPLEST, N, device="cuda") as env:
        env.reset(seed=5)
        with pytest.raises(ValueError, match="byte stride 9 is not a multiple of the item size 8"):
            env.step(Interface(raw, raw.data_ptr(), "<i8", (9,)))


def test_a_misaligned_device_pointer_is_refused():
    raw = torch.zeros(8 * N + 8, dtype=torch.uint8, device="cuda")
    with kage.make_vec(SIMPLEST, N, device="cuda") as env:
        env.reset(seed=5)
        with pytest.raises(ValueError, match="not aligned"):
            env.step(Interface(raw, raw.data_ptr() + 1, "<i8", None))
