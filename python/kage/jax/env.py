"""kage.jax's environment: ``reset`` and ``step`` as pure functions of a state pytree, each one typed XLA
FFI call (``kage/jax/_ffi.py``), so that ``jax.jit``, ``lax.scan`` and ``jax.vmap`` take them whole."""
import dataclasses
import os
from typing import Any, Dict, Tuple, Union

import jax
import jax.numpy as jnp
import numpy as np

from kage import fields, spaces, vector
from kage.jax import _ffi, _native
from kage.jax.seeds import env_seed_words

_INFO_NAMES = tuple(name for name, _, _ in vector.INFO_FIELDS)
_BATCH_NAMES = ("config",)  # the batch's fields that JaxEnv._batch_fields fills
if _BATCH_NAMES != fields.BATCH_FIELDS:
    raise ImportError(f"kage.jax fills the batch fields {_BATCH_NAMES}, kage.fields lists {fields.BATCH_FIELDS}")
_FINAL_KEYS = ("final_obs", "final_info", "_final", "_final_obs", "_final_info")


@dataclasses.dataclass(frozen=True)
class KageState:
    """Everything a batch of environments needs to continue: the parts of ``kage.VecEnv.save_state``'s
    format (seeds, latent and visual states, layouts) plus the last finished episodes' final observation
    and info and the out-of-range action record. Only 8- and 32-bit arrays (JAX's default has no 64-bit
    types). Its ``spec_hash`` is static (pytree metadata): a state of one config is refused by another.

    - ``seeds`` uint32 [N, 2]: each environment's 64-bit seed as (low, high) words;
    - ``latent``, ``segments``, ``visual`` uint8 [N, bytes]: the runtime's state structs and layouts;
    - ``final_obs``, ``final_info``: see ``JaxEnv.step``;
    - ``steps`` int32 []: steps since the reset;
    - ``action_error`` int32 [N, 2]: per environment, (value, step) of its first action outside 0..7,
      (0, 0) while there is none; ``JaxEnv.check`` raises it.
    """

    seeds: Any
    latent: Any
    segments: Any
    visual: Any
    final_obs: Any
    final_info: Dict[str, Any]
    steps: Any
    action_error: Any
    spec_hash: str


_ARRAY_FIELDS = ("seeds", "latent", "segments", "visual", "final_obs", "final_info", "steps", "action_error")
jax.tree_util.register_dataclass(KageState, data_fields=list(_ARRAY_FIELDS), meta_fields=["spec_hash"])


class JaxEnv:
    """``num_envs`` environments of one config as two pure functions:

    ``reset(seed) -> (state, obs, info)`` and ``step(state, actions) -> (state, obs, reward, terminated,
    truncated, info)``, with the names, shapes and dtypes of ``kage.make_vec``'s outputs: obs uint8
    [N, H, W, 3], reward float32 [N], flags and masks as make_vec gives them, info the fields of
    ``kage.INFO_FIELDS``, the batch's (``config``: 0, one config) and the same-step autoreset keys
    ``final_obs``, ``final_info``, ``_final``, ``_final_obs`` and ``_final_info``.

    Same-step autoreset, as make_vec: a step that ends an episode returns its reward and flags, the next
    episode's first observation and info, and the finished episode's last observation and info in
    ``final_obs`` / ``final_info`` where ``_final`` is true. Rows where ``_final`` is false hold that
    environment's previous final observation and info (zeros until its first episode ends): the state
    carries them, so a step writes only the rows that finish.
    """

    metadata = {"autoreset_mode": "same-step"}

    def __init__(self, config: str, num_envs: int, sizes: Dict[str, Any], dtypes: Dict[str, Any]):
        self.config = config
        self.num_envs = num_envs
        self.spec_hash = sizes["spec_hash"]
        height, width = sizes["height"], sizes["width"]
        self.single_observation_space = spaces.observation_space(height, width)
        self.single_action_space = spaces.action_space()
        n = num_envs
        sd = jax.ShapeDtypeStruct
        self._obs = sd((n, height, width, 3), dtypes["obs"])
        self._info = {name: sd((n,), dtypes[name]) for name in _INFO_NAMES}
        flag = sd((n,), dtypes["flag"])
        self._outputs = [self._obs, sd((n,), dtypes["reward"]), flag, flag, sd((n,), dtypes["final"])]
        self._state = KageState(
            seeds=sd((n, 2), jnp.uint32), latent=sd((n, sizes["latent_bytes"]), jnp.uint8),
            segments=sd((n, sizes["segment_bytes"]), jnp.uint8), visual=sd((n, sizes["visual_bytes"]), jnp.uint8),
            final_obs=self._obs, final_info=dict(self._info), steps=sd((), jnp.int32),
            action_error=sd((n, 2), jnp.int32), spec_hash=self.spec_hash)

    # ---- the two calls ----

    def reset(self, seed) -> Tuple[KageState, Any, Dict[str, Any]]:
        """Starts episode 0 of every environment. ``seed``: a non-negative Python int, or a uint32 JAX
        scalar (traced or not); environment i gets ``kage.env_seeds(seed, num_envs)[i]``, as
        ``kage.make_vec``'s ``reset(seed=seed)`` gives it."""
        return self._reset_words(seed_words(seed, self.num_envs))

    def _reset_words(self, words) -> Tuple[KageState, Any, Dict[str, Any]]:
        """reset() with each environment's seed given: uint32 [num_envs, 2] (low, high) words."""
        s = self._state
        outs = _ffi.reset_call([s.latent, s.segments, s.visual, *self._outputs, *self._info.values()])(
            words, spec_hash=self.spec_hash)
        latent, segments, visual, obs, _, _, _, final_mask = outs[:8]
        info = dict(zip(_INFO_NAMES, outs[8:]))
        state = KageState(
            seeds=words, latent=latent, segments=segments, visual=visual,
            final_obs=jnp.zeros(self._obs.shape, self._obs.dtype),
            final_info={name: jnp.zeros(a.shape, a.dtype) for name, a in self._info.items()},
            steps=jnp.int32(0), action_error=jnp.zeros((self.num_envs, 2), jnp.int32), spec_hash=self.spec_hash)
        return state, obs, self._with_final(info, state, final_mask)

    def step(self, state: KageState, actions) -> Tuple[KageState, Any, Any, Any, Any, Dict[str, Any]]:
        """One step of every environment with ``actions``: int32 [num_envs], each in 0..7 (bit 0 left,
        bit 1 right, bit 2 jump). A value outside 0..7 is recorded in the state (``check`` raises it) and
        the step runs with its low 3 bits, as the runtime masks any action (spec 3.2)."""
        self._check_state(state)
        actions = checked_actions(actions, self.num_envs)
        s = self._state
        finals = [state.final_info[name] for name in _INFO_NAMES]
        outs = _ffi.step_call([s.latent, s.segments, s.visual, s.final_obs, *self._outputs, s.latent, s.segments,
                               s.visual, *self._info.values(), *self._info.values()])(
            state.seeds, state.latent, state.segments, state.visual, state.final_obs, actions, *finals,
            spec_hash=self.spec_hash)
        latent, segments, visual, final_obs, obs, reward, terminated, truncated, final_mask = outs[:9]
        k = len(_INFO_NAMES)
        final_info = dict(zip(_INFO_NAMES, outs[12:12 + k]))
        info = dict(zip(_INFO_NAMES, outs[12 + k:]))
        steps = state.steps + 1
        bad = (actions < 0) | (actions > 7)
        first = bad & (state.action_error[:, 1] == 0)
        record = jnp.stack([actions, jnp.broadcast_to(steps, actions.shape)], axis=1)
        new = KageState(seeds=state.seeds, latent=latent, segments=segments, visual=visual, final_obs=final_obs,
                        final_info=final_info, steps=steps,
                        action_error=jnp.where(first[:, None], record, state.action_error), spec_hash=self.spec_hash)
        return new, obs, reward, terminated, truncated, self._with_final(info, new, final_mask)

    def check(self, state: KageState) -> None:
        """Raises ValueError if any step since the reset had an action outside 0..7 (naming the first);
        call it outside ``jit`` (it reads the [N, 2] record from the device), e.g. after a scan. A state with
        leading vmap axes is checked whole. Inside ``jit``, ``vmap`` or ``scan`` it raises TypeError saying so."""
        self._check_state(state, batched=True)
        check_action_record(state.action_error)

    def __repr__(self) -> str:
        return f"<kage.jax.JaxEnv {self.config!r}, {self.num_envs} envs, spec {self.spec_hash[:12]}>"

    # ---- checks at trace time ----

    def _check_state(self, state, batched: bool = False) -> None:
        if not isinstance(state, KageState):
            raise TypeError(f"state: expected the KageState that this environment's reset or step returned, "
                            f"got {type(state).__name__}")
        if state.spec_hash != self.spec_hash:
            raise ValueError(f"state: it belongs to the config with spec hash {state.spec_hash[:16]}..., but this "
                             f"environment runs {self.config} (spec hash {self.spec_hash[:16]}...): give each "
                             "environment the state its own reset returned")
        for field in _ARRAY_FIELDS:
            got, want = getattr(state, field), getattr(self._state, field)
            pairs = [(f"{field}[{k!r}]", got.get(k), w) for k, w in want.items()] if field == "final_info" \
                else [(field, got, want)]
            for name, g, w in pairs:
                shape = getattr(g, "shape", None)
                if shape is None or (shape[len(shape) - len(w.shape):] if batched else shape) != w.shape:
                    raise ValueError(f"state.{name}: shape {shape}, expected {w.shape} for {self.num_envs} "
                                     "environments of this config")
                if g.dtype != w.dtype:
                    raise TypeError(f"state.{name}: dtype {g.dtype}, expected {w.dtype}")

    def _batch_fields(self) -> Dict[str, Any]:
        """The batch's fields (kage.fields.BATCH_FIELDS), constants of the graph: one config, index 0."""
        return {"config": jnp.zeros((self.num_envs,), jnp.int32)}

    def _with_final(self, info: Dict[str, Any], state: KageState, final_mask) -> Dict[str, Any]:
        batch = self._batch_fields()
        out = dict(info, **batch)
        final_info = dict(state.final_info, **batch)  # a finished episode ran the same config
        out.update(zip(_FINAL_KEYS, (state.final_obs, final_info, final_mask, final_mask, final_mask)))
        return out


def seed_words(seed, n: int):
    """uint32 [n, 2]: the seeds of ``kage.env_seeds(seed, n)`` as (low, high) words, for a non-negative int or a
    uint32 JAX scalar (traced or not); TypeError or ValueError naming what the seed should be."""
    if isinstance(seed, (bool, np.bool_)):
        raise TypeError(f"seed={seed!r}: a non-negative int or a uint32 scalar")
    if isinstance(seed, (int, np.integer)):
        if int(seed) < 0:
            raise ValueError(f"seed={seed}: a non-negative integer (numpy's SeedSequence takes no negative seed)")
        if int(seed) >= 2**32:  # beyond one uint32 word: the same seeds, derived on the host
            return jnp.asarray(vector.env_seeds(int(seed), n).view(np.uint32).reshape(n, 2))
        seed = jnp.uint32(seed)
    if not hasattr(seed, "shape") or not hasattr(seed, "dtype"):
        raise TypeError(f"seed: a non-negative int or a uint32 scalar, got {type(seed).__name__}")
    if seed.shape != () or seed.dtype != jnp.uint32:
        raise TypeError(f"seed: a non-negative int or a uint32 scalar, got {seed.dtype} of shape {seed.shape} "
                        "(jnp.uint32(s) or x.astype(jnp.uint32); under vmap, one uint32 per batch)")
    return env_seed_words(seed, n)


def check_action_record(action_error) -> None:
    """Raises ValueError naming the first out-of-range action of an action record ([..., N, 2], leading vmap
    axes allowed), TypeError inside jit, vmap or scan."""
    if isinstance(action_error, jax.core.Tracer):
        raise TypeError("env.check(state) reads the state's action record back from the device, so it runs outside "
                        "jax.jit, vmap and scan: call it on the state that your jitted function returns (after the "
                        "scan, say), not inside it")
    record = np.asarray(jax.device_get(action_error))
    hits = np.argwhere(record[..., 1] != 0)
    if hits.size == 0:
        return
    steps = record[..., 1][tuple(hits.T)]
    where = tuple(hits[np.lexsort((np.arange(len(hits)), steps))[0]])
    value, step = record[where]
    batch = f" of batch {where[:-1]}" if len(where) > 1 else ""
    more = f" ({len(hits)} environments had one)" if len(hits) > 1 else ""
    raise ValueError(f"kage.jax: the actions of step {step} held {value} for environment {where[-1]}{batch}"
                     f"{more}: {vector.native().action_range_text()}; that step ran with the value masked to "
                     "its low 3 bits")


def checked_actions(actions, num_envs: int):
    """`actions` as one int32 JAX array of shape [num_envs] (host values converted first), or ValueError or
    TypeError naming `actions`: what a JaxEnv's and a JaxMixture's step take."""
    shape, dtype = getattr(actions, "shape", None), getattr(actions, "dtype", None)
    if shape is None or dtype is None:
        actions = _host_actions(actions, num_envs)
        shape, dtype = actions.shape, actions.dtype
    if tuple(shape) != (num_envs,):
        raise ValueError(f"actions: shape {tuple(shape)}, expected ({num_envs},): one action per environment")
    if dtype != jnp.int32:
        raise TypeError(f"actions: dtype {dtype}, expected int32 (e.g. jax.random.categorical's output, or "
                        "actions.astype(jnp.int32))")
    return jnp.asarray(actions)


def _host_actions(actions, num_envs: int):
    """Actions given as a Python sequence (a list of ints): an int32 array, or TypeError / ValueError naming
    ``actions`` where they are not integers that int32 holds. Strings are refused, not parsed."""
    expected = f"expected int32 [{num_envs}], one action in 0..7 per environment"
    if isinstance(actions, (str, bytes)):
        raise TypeError(f"actions={actions!r:.40}: a {type(actions).__name__}, {expected}")
    try:
        values = np.asarray(actions)
    except (TypeError, ValueError, OverflowError) as e:
        raise TypeError(f"actions: a {type(actions).__name__} that is not an array of integers ({e}); {expected}") \
            from None
    integers = values.dtype.kind in "iu" or (values.dtype.kind == "O" and all(  # "O": ints beyond 64 bits
        isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in values.reshape(-1).tolist()))
    if not integers:
        raise TypeError(f"actions: {values.dtype} values ({str(actions)[:40]}), {expected}")
    big = [int(v) for v in values.reshape(-1).tolist() if not -2**31 <= int(v) < 2**31]
    if big:
        raise ValueError(f"actions: {big[0]} does not fit int32 (and actions are 0..7); {expected}")
    return jnp.asarray(values.astype(np.int32))


def make_config_env(config: Union[str, os.PathLike], num_envs: int, asset_root=None) -> JaxEnv:
    """``num_envs`` environments of ``config`` (a YAML file or a ``kagec compile`` directory) for JAX
    (``kage.jax.make_env`` for one config).

    Raises what ``kage.make_vec`` raises for the same config: ``kage.ConfigError`` with kagec's located
    diagnostics, ``FileNotFoundError``, ``ValueError`` for bad arguments. ``asset_root`` as make_vec's.
    ``num_envs`` has make_vec's limits: at most 2**31 - 1, and no more environments than make_vec builds on
    the CPU (their states, observations and render scratch within half of the machine's memory), on every
    backend; beyond them it raises ValueError with make_vec's words before anything is allocated.
    """
    if not vector._is_integer(num_envs) or not 0 < num_envs <= vector.MAX_INT32:
        raise ValueError(f"num_envs={num_envs!r}: a positive integer up to {vector.MAX_INT32}")
    # One CPU environment of make_vec: its errors, its resolved path and the dtypes of its outputs.
    probe = vector.make_vec(config, 1, device="cpu", threads=1, asset_root=asset_root)
    try:
        obs, _ = probe.reset(seed=0)
        _, reward, terminated, _, info = probe.step(np.zeros(1, np.int32))
        dtypes = {"obs": obs.dtype, "reward": reward.dtype, "flag": terminated.dtype, "final": info["_final"].dtype,
                  **{name: info[name].dtype for name in _INFO_NAMES}}
        path, spec_hash = probe.config, probe.spec_hash
    finally:
        probe.close()
    _ffi.register()
    sizes = _native.module().register_config(path, os.fspath(asset_root) if asset_root else "")
    if sizes["spec_hash"] != spec_hash:
        raise RuntimeError(f"kage.jax: {path} has spec hash {sizes['spec_hash']} here but {spec_hash} in make_vec: "
                           "kage._kage and kage._kage_jax come from different builds; reinstall")
    refusal = _native.module().memory_refusal(spec_hash, int(num_envs))
    if refusal:
        raise ValueError(f"kage.jax.make_env: num_envs={int(num_envs)}: {refusal}")
    return JaxEnv(path, int(num_envs), sizes, dtypes)
