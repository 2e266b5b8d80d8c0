"""kage.jax: KAGE environments for JAX learners. ``reset`` and ``step`` are pure functions over a state
pytree, each one typed XLA FFI call, so a PureJaxRL-style agent keeps its whole iteration in one ``jit``:

    import jax, kage.jax
    env = kage.jax.make_env("configs/throughput/simplest.yaml", 64)
    state, obs, info = env.reset(0)
    step = jax.jit(env.step, donate_argnums=0)   # donation: XLA updates the state in place
    state, obs, reward, terminated, truncated, info = step(state, actions)

A list of configs that differ only on visual axes makes a mixture (``JaxMixture``, as ``kage.make_vec``'s).
See ``make_env``, ``JaxEnv`` and the README's "JAX" section (vmap, mixtures, errors, tested versions).
"""
try:
    import jax  # noqa: F401  (absolute: the real JAX, not this package)
except ImportError as e:
    raise ImportError("kage.jax needs JAX: `pip install jax` (CPU) or `pip install 'jax[cuda13]'` (NVIDIA GPUs); "
                      "see README, JAX, for the tested versions") from e

from kage.jax.env import JaxEnv, KageState
from kage.jax.mixture import JaxMixture, MixtureState, make_env

__all__ = ["JaxEnv", "JaxMixture", "KageState", "MixtureState", "make_env"]
