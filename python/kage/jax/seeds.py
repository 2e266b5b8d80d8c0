"""The per-environment seeds of ``kage.env_seeds`` (numpy's ``SeedSequence(seed).generate_state(n, uint64)``),
derived inside the graph from a uint32 seed, bit for bit, in 32-bit arithmetic only: JAX runs with 64-bit
types off by default.

Each 64-bit seed is a pair of uint32 words (low, high), as numpy assembles it from little-endian words.
The constants and steps are those of numpy's ``SeedSequence`` (O'Neill's seed_seq hash): a pool of four
words mixed from the entropy, then ``2 * n`` output words hashed from the pool.
"""
import functools

import jax.numpy as jnp
import numpy as np

_INIT_A, _MULT_A = 0x43B0D7E5, 0x931E8875  # the pool's hash constants
_INIT_B, _MULT_B = 0x8B51F9DD, 0x58F38DED  # the output's hash constants
_MIX_L, _MIX_R = 0xCA01F9DD, 0x4973F715
_POOL = 4


def _powers(init: int, mult: int, count: int) -> np.ndarray:
    """init * mult**k mod 2**32 for k = 0 .. count-1 (the hash constant before each use): a running product in
    uint32, which wraps modulo 2**32 (one pass in numpy: a batch's 2 N constants in milliseconds)."""
    factors = np.full(count, mult, dtype=np.uint32)
    factors[:1] = init
    return np.cumprod(factors, dtype=np.uint32)


def _u32(x: int):
    return jnp.uint32(x)


def _xorshift(v):
    return v ^ (v >> jnp.uint32(16))


def _pool(seed):
    """The four pool words of SeedSequence(seed) for one uint32 entropy word: 4 + 12 hashmix calls, each
    with the next constant of the INIT_A * MULT_A**k sequence."""
    h = _powers(_INIT_A, _MULT_A, 4 + _POOL * (_POOL - 1) + 1)
    calls = iter(range(len(h) - 1))

    def hashmix(v):
        k = next(calls)
        return _xorshift((v ^ _u32(h[k])) * _u32(h[k + 1]))

    def mix(x, y):
        return _xorshift(_u32(_MIX_L) * x - _u32(_MIX_R) * y)

    pool = [hashmix(seed)] + [hashmix(_u32(0)) for _ in range(_POOL - 1)]
    for src in range(_POOL):
        for dst in range(_POOL):
            if src != dst:
                pool[dst] = mix(pool[dst], hashmix(pool[src]))
    return jnp.stack(pool)


@functools.lru_cache(maxsize=None)
def _output_constants(words: int):
    """Per output word: the pool index, the constant it is XORed with and the one it is multiplied by."""
    h = _powers(_INIT_B, _MULT_B, words + 1)
    return np.arange(words) % _POOL, h[:-1], h[1:]


def env_seed_words(seed, num_envs: int):
    """uint32 [num_envs, 2]: environment i's seed of ``kage.env_seeds(seed, num_envs)`` as (low, high)
    words. ``seed``: a uint32 scalar (traced or not)."""
    index, xor, mul = _output_constants(2 * num_envs)
    words = _xorshift((_pool(seed)[index] ^ jnp.asarray(xor)) * jnp.asarray(mul))
    return words.reshape(num_envs, 2)
