"""Every array that crosses into C++ (actions, seeds, reset masks, saved states) is read as the values Python
sees, whatever its layout: byte strides that are not a multiple of the item size, either byte order,
misaligned data, negative and zero strides, read-only memory. The binding itself refuses a layout it cannot
read, naming it, rather than reading other bytes."""
import numpy as np
import pytest

import kage
from support import SIMPLEST

N = 6
ACTIONS = np.array([2, 6, 0, 7, 1, 4], dtype=np.int64)


def state_after(actions) -> bytes:
    with kage.make_vec(SIMPLEST, N, threads=1) as env:
        env.reset(seed=5)
        env.step(actions)
        return env.save_state()


@pytest.fixture(scope="module")
def expected() -> bytes:
    return state_after(ACTIONS.copy())


def packed_field(values: np.ndarray, kind: str) -> np.ndarray:
    """`values` as field "b" of a packed structured array: one byte "a" before it, so the byte stride is the
    item size + 1 and the data is misaligned. Field "a" holds 255, which a reader of other bytes would see."""
    record = np.zeros(len(values), dtype=np.dtype([("a", "u1"), ("b", kind)], align=False))
    record["a"] = 255
    record["b"] = values
    return record["b"]


def misaligned(values: np.ndarray, kind: str) -> np.ndarray:
    buffer = bytearray(1 + len(values) * np.dtype(kind).itemsize)
    array = np.frombuffer(buffer, dtype=kind, offset=1, count=len(values))
    array[:] = values
    return array


def read_only(values: np.ndarray) -> np.ndarray:
    array = values.copy()
    array.flags.writeable = False
    return array


@pytest.mark.parametrize("make", [
    lambda: packed_field(ACTIONS, "<i8"),
    lambda: packed_field(ACTIONS, "<i4"),
    lambda: packed_field(ACTIONS, ">i8"),
    lambda: packed_field(ACTIONS, "<u2"),
    lambda: ACTIONS.astype(">i8"),
    lambda: ACTIONS.astype(">i4"),
    lambda: misaligned(ACTIONS, "<i8"),
    lambda: misaligned(ACTIONS, "<i4"),
    lambda: read_only(ACTIONS),
    lambda: np.repeat(ACTIONS, 3)[::3],
    lambda: ACTIONS[::-1].copy()[::-1],
    lambda: np.lib.stride_tricks.as_strided(ACTIONS.astype(np.int32), shape=(N,), strides=(4,)),
], ids=["packed-i8", "packed-i4", "packed-big-i8", "packed-u2", "big-i8", "big-i4", "misaligned-i8",
        "misaligned-i4", "read-only", "stride-3", "negative-stride", "as-strided"])
def test_host_actions_of_any_layout_step_as_their_values(make, expected):
    actions = make()
    assert actions.tolist() == ACTIONS.tolist()
    assert state_after(actions) == expected


def test_a_masked_array_steps_as_its_values_or_is_refused(expected):
    # Nothing masked: the values. A masked element has no value: refused, never the hidden number behind it.
    assert state_after(np.ma.masked_array(ACTIONS, mask=False)) == expected
    hidden = np.ma.masked_array(ACTIONS, mask=[False, True, False, False, False, False])
    with kage.make_vec(SIMPLEST, N, threads=1) as env:
        env.reset(seed=5)
        with pytest.raises(ValueError, match="a masked array with masked elements"):
            env.step(hidden)


def test_broadcast_actions_are_one_value_for_all():
    assert state_after(np.broadcast_to(np.int64(6), (N,))) == state_after(np.full(N, 6))


@pytest.mark.parametrize("make, layout", [
    (lambda: packed_field(ACTIONS, "<i8"), "byte stride 9 is not a multiple of the item size 8"),
    (lambda: misaligned(ACTIONS, "<i8"), "not aligned"),
    (lambda: ACTIONS.astype(">i8"), "byte order"),
])
def test_the_binding_refuses_a_layout_it_cannot_read(make, layout):
    with kage.make_vec(SIMPLEST, N, threads=1) as env:
        env.reset(seed=5)
        with pytest.raises(ValueError, match=layout):
            env._handle.step_host(make())


SEEDS = np.array([3, 1, 4, 1, 5, 2**64 - 1], dtype=np.uint64)


@pytest.mark.parametrize("make", [
    lambda: SEEDS.astype(">u8"),
    lambda: packed_field(SEEDS, "<u8"),
    lambda: misaligned(SEEDS, "<u8"),
    lambda: np.repeat(SEEDS, 2)[::2],
    lambda: read_only(SEEDS),
], ids=["big-u8", "packed", "misaligned", "stride-2", "read-only"])
def test_seeds_of_any_layout_are_their_values(make):
    with kage.make_vec(SIMPLEST, N, threads=1) as a, kage.make_vec(SIMPLEST, N, threads=1) as b:
        a.reset(seed=SEEDS.copy())
        b.reset(seed=make())
        assert a.save_state() == b.save_state()
        a._handle.reset(SEEDS.copy(), None)
        b._handle.reset(make(), None)
        assert a.save_state() == b.save_state()


MASK = np.array([True, False, True, False, False, True])


@pytest.mark.parametrize("make", [
    lambda: packed_field(MASK, "?"),
    lambda: np.repeat(MASK, 2)[::2],
    lambda: read_only(MASK),
    lambda: MASK.astype(">i4"),
], ids=["packed-bool", "stride-2", "read-only", "big-i4"])
def test_reset_masks_of_any_layout_are_their_values(make):
    with kage.make_vec(SIMPLEST, N, threads=1) as a, kage.make_vec(SIMPLEST, N, threads=1) as b:
        for env, mask in ((a, MASK.copy()), (b, make())):
            env.reset(seed=1)
            env.step(ACTIONS)
            env.reset(seed=9, options={"reset_mask": mask})
        assert a.save_state() == b.save_state()


@pytest.mark.parametrize("wrap", [
    bytes, bytearray, memoryview, lambda s: np.frombuffer(s, dtype=np.uint8), lambda s: memoryview(bytes(s)).toreadonly(),
    lambda s: memoryview(np.repeat(np.frombuffer(s, dtype=np.uint8), 2))[::2],
], ids=["bytes", "bytearray", "memoryview", "numpy-u8", "read-only", "stride-2"])
def test_saved_state_from_any_bytes_like_restores(wrap):
    with kage.make_vec(SIMPLEST, N, threads=1) as env, kage.make_vec(SIMPLEST, N, threads=1) as copy:
        env.reset(seed=2)
        env.step(ACTIONS)
        state = env.save_state()
        copy.load_state(wrap(state))
        assert copy.save_state() == state


@pytest.mark.parametrize("state, match", [
    (np.zeros(8, dtype=np.int32), "bytes"),
    ("KAGEBST", "bytes"),
    (12, "bytes"),
])
def test_saved_state_that_is_not_bytes_is_refused(state, match):
    with kage.make_vec(SIMPLEST, N, threads=1) as env, pytest.raises(ValueError, match=match):
        env.load_state(state)
