"""VecEnv: a batch of KAGE environments with Gymnasium 1.x's vector signatures (same-step autoreset).

Outputs are views of the runtime's memory, not copies: numpy arrays on the CPU, ``kage.DeviceArray`` on
the GPU (take them with ``torch.from_dlpack``, ``jax.dlpack.from_dlpack`` or ``cupy.asarray``). A view
stays allocated while it exists, but its contents are overwritten by the next ``reset`` or ``step``:
copy what you keep (``obs.copy()``, ``tensor.clone()``), or make a CPU batch with ``copy=True``.
"""
import contextlib
import json
import os
import threading
import warnings
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from kage import actions as _actions, fields, front_end, mixture as _mixture, resources, spaces
from kage._native import native
from kage.errors import ConfigWarning

#: (name, numpy dtype, meaning) of every info field the runtime writes, in its order (runtime/info_fields.def).
INFO_FIELDS = tuple(native().info_fields())
_problem = fields.runtime_problem([name for name, _, _ in INFO_FIELDS])
if _problem:
    raise ImportError(f"kage: {_problem}")
#: The names of info's per-environment arrays: the runtime's fields, then the batch's (kage.fields.BATCH_FIELDS).
INFO_NAMES = tuple(name for name, _, _ in INFO_FIELDS) + fields.BATCH_FIELDS

Seed = Union[int, Sequence[int], None]


def env_seeds(seed: int, num_envs: int) -> np.ndarray:
    """The per-environment seeds of ``reset(seed=seed)``: independent 64-bit draws of numpy's
    ``SeedSequence(seed)``, so runs with different seeds share no environment stream."""
    return np.random.SeedSequence(seed).generate_state(num_envs, dtype=np.uint64)


MAX_INT32 = 2**31 - 1  # the runtime's environment and thread counts are int32


def _is_integer(value) -> bool:
    """An int or numpy integer (a 0-d integer array too), not a bool: values that floats or strings would
    only approximate are refused, never truncated."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value[()]
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _seed_value(seed, what: str = "seed") -> int:
    """A seed as a Python int: a non-negative integer, anything else refused (1.5 is not seed 1)."""
    if not _is_integer(seed) or int(seed) < 0:
        raise ValueError(f"{what}={seed!r:.80}: a non-negative integer")
    return int(seed)


def _explicit_seeds(seed, num_envs: int) -> np.ndarray:
    """num_envs integers in [0, 2^64) as uint64 (Python ints above 2^63 would become float64 in numpy)."""
    values = list(seed)
    if len(values) != num_envs or not all(_is_integer(v) and 0 <= int(v) < 2**64 for v in values):
        raise ValueError(f"seed: an int or {num_envs} non-negative ints below 2**64, got {seed!r:.80}")
    return np.array([int(v) for v in values], dtype=np.uint64)


def _reset_mask(value, num_envs: int) -> np.ndarray:
    """options["reset_mask"] as uint8 0/1: booleans, or integers that are all 0 or 1; floats (0.5, NaN) and
    other integers (256 would wrap to 0) are refused rather than cast."""
    mask = np.asarray(value)
    if mask.shape != (num_envs,):
        raise ValueError(f"options['reset_mask']: expected {num_envs} booleans, got shape {mask.shape}")
    if mask.dtype.kind in "iu":
        bad = sorted(set(mask[(mask != 0) & (mask != 1)].tolist()))
        if bad:
            raise ValueError(f"options['reset_mask']: booleans or 0/1, got {', '.join(map(str, bad[:5]))}")
    elif mask.dtype.kind != "b":
        raise ValueError(f"options['reset_mask']: booleans or 0/1 integers, got dtype {mask.dtype}")
    return mask.astype(np.uint8)


def _state_bytes(state) -> Any:
    """A saved state as a contiguous buffer of bytes, without a copy where it is one already."""
    try:
        view = memoryview(state)
    except TypeError:
        view = None
    if view is None or view.itemsize != 1 or view.format not in ("B", "b", "c"):
        what = type(state).__name__ if view is None else f"{type(state).__name__} of format {view.format!r}"
        raise ValueError(f"load_state: expects the bytes of save_state() (bytes, bytearray, memoryview or a uint8 "
                         f"array), got {what}")
    return view if view.c_contiguous and view.ndim == 1 else view.tobytes()


class VecEnv(spaces.VectorEnvBase):
    """``num_envs`` environments of one configuration (or of a mixture: ``make_vec``), stepped together.

    ``reset(seed=None, options=None) -> (obs, info)`` and
    ``step(actions) -> (obs, reward, terminated, truncated, info)``: obs uint8 [N, H, W, 3], reward
    float32 [N], terminated and truncated bool [N], info a dict of [N] arrays named as the original's
    info (``x``, ``y``, ``vx``, ``vy``, ``vx_mean``, ``vy_mean``, ``timestep``, ``passed_distance``,
    ``progress``, ``success``, ``success_once``, ``jump_count``, ``return``, ``length``), and ``config``
    (int32: the index of the config each environment runs; 0 for a batch of one config). kage.fields
    lists them (``INFO_NAMES``).

    Same-step autoreset: when a step ends an episode, that environment starts its next episode in the
    same step. The step returns the finishing step's reward and flags, the new episode's first
    observation and info, and the finished episode in ``info["final_obs"]`` and ``info["final_info"]``
    (a dict of the same fields), where the bool mask ``info["_final"]`` is true (so ``final_obs[info["_final"]]``
    selects the finished rows). Rows where ``_final`` is false hold an earlier episode's end, or zeros.

    Gymnasium: where it is importable, this is a ``gymnasium.vector.VectorEnv`` (its vector wrappers, such as
    ``RecordEpisodeStatistics``, take it), ``metadata["autoreset_mode"]`` is ``AutoresetMode.SAME_STEP`` and
    ``observation_space``/``action_space`` are the batched spaces; ``gymnasium.make_vec("kage/KAGE-v0", ...)``
    returns this class (``kage.registration``) and sets ``spec`` to its ``EnvSpec``. The batch's resolved Spec
    is ``resolved_spec``.

    Threads: a batch may be used from any thread, and calls from several threads run one at a time, each
    one whole (a step's state is never torn, ``save_state`` never sees half a step). ``close()`` (and
    deleting or collecting the batch) waits for a call in progress on another thread; later calls raise
    ``RuntimeError``, as does a call made from inside another on the same thread (an actions object whose
    ``__array__`` calls back into the batch). The outputs are one set of views for all threads: a thread
    that reads them while another steps sees that step's values, so give a batch to one thread at a time,
    or copy what you keep.
    On the GPU, closing waits for the device's queued work before the batch's memory is freed.
    """

    metadata = {"autoreset_mode": spaces.SAME_STEP}
    spec = None  # Gymnasium's EnvSpec, where gymnasium.make_vec made the batch
    render_mode = None

    def __init__(self, handle: "kage._kage.Env", config: Union[str, List[str]], seed: int,
                 asset_root: Optional[str] = None, counts: Optional[Sequence[int]] = None, copy: bool = False):
        self._handle = handle
        self._copy = copy  # reset, step and load_state return copies instead of the runtime's buffers
        self._lock = threading.Lock()  # one call at a time (see Threads above)
        self._caller: Optional[int] = None  # the thread inside a call, which a re-entrant call must not wait for
        self.config = config  # as make_vec was given it: a path, or a mixture's list of paths
        self.configs: Tuple[str, ...] = (config,) if isinstance(config, str) else tuple(config)
        self._asset_root = asset_root
        self._spec: Optional[dict] = None
        self._specs: Optional[List[dict]] = None
        self.num_envs = handle.num_envs
        #: How many environments run each config (config 0's first: info["config"]).
        self.counts: Tuple[int, ...] = (self.num_envs,) if counts is None else tuple(int(c) for c in counts)
        self.device = handle.device
        self.spec_hash = handle.spec_hash
        self.single_observation_space = spaces.observation_space(handle.height, handle.width)
        self.single_action_space = spaces.action_space()
        self.observation_space = spaces.batched(self.single_observation_space, self.num_envs)
        self.action_space = spaces.batched(self.single_action_space, self.num_envs)
        self._seed = seed
        self._resets_without_seed = 0
        self._last_actions = None
        out = handle.output
        self._obs = out("obs")
        self._reward = out("reward")
        self._terminated = out("terminated")
        self._truncated = out("truncated")
        self._info = {name: out(f"info/{name}") for name in INFO_NAMES}
        final_mask = out("final_mask")
        final_info = {name: out(f"final_info/{name}") for name in INFO_NAMES}
        # Gymnasium 1.x same-step keys; _final_obs and _final_info are the same mask as _final.
        self._final = {
            "final_obs": out("final_obs"),
            "final_info": final_info,
            "_final": final_mask,
            "_final_obs": final_mask,
            "_final_info": final_mask,
        }

    # ---- Gymnasium vector API ----

    def reset(self, seed: Seed = None, options: Optional[Dict[str, Any]] = None) -> Tuple[Any, Dict[str, Any]]:
        """Starts episode 0 of every environment (or of those where ``options["reset_mask"]`` is true;
        the others keep their state). ``seed``: an int (each environment gets its own seed from it,
        see ``env_seeds``), ``num_envs`` ints (the environments' own seeds), or None (make_vec's seed
        on the first call, then a fresh draw from it on each later call)."""
        with self._one_call():
            return self._reset(seed, options)

    def _reset(self, seed: Seed, options: Optional[Dict[str, Any]]) -> Tuple[Any, Dict[str, Any]]:
        handle = self._live()
        if seed is None:
            seeds = np.random.SeedSequence([self._seed, self._resets_without_seed]).generate_state(
                self.num_envs, dtype=np.uint64) if self._resets_without_seed else env_seeds(self._seed, self.num_envs)
            self._resets_without_seed += 1
        elif np.ndim(seed) == 0:
            seeds = env_seeds(_seed_value(seed), self.num_envs)
        else:
            seeds = _explicit_seeds(seed, self.num_envs)
        mask = None
        options = dict(options or {})
        if "reset_mask" in options:
            mask = _reset_mask(options.pop("reset_mask"), self.num_envs)
        if options:
            raise ValueError(f"reset: unknown options {sorted(options)} (known: 'reset_mask')")
        handle.reset(seeds, mask)
        return self._returned((self._obs, self._info_dict()))

    def step(self, actions) -> Tuple[Any, Any, Any, Any, Dict[str, Any]]:
        """One step of every environment; ``actions``: [num_envs] integers in 0..7 (numpy, torch,
        JAX, CuPy, ...; read in place on the GPU)."""
        with self._one_call():
            handle = self._live()
            _actions.submit(handle, actions)
            # The runtime reads device actions when its kernel runs: keep them alive until the next step.
            self._last_actions = actions
            return self._returned((self._obs, self._reward, self._terminated, self._truncated, self._info_dict()))

    def outputs(self) -> Tuple[Any, Any, Any, Any, Dict[str, Any]]:
        """The arrays of the last reset or step, (obs, reward, terminated, truncated, info), without
        stepping: the same views every call, so a learner can take them once and read them each step."""
        with self._one_call():
            self._live()
            return self._obs, self._reward, self._terminated, self._truncated, self._info_dict()

    def close(self) -> None:
        """Releases the environments. Arrays and tensors still viewing their outputs keep that memory
        alive until they are dropped. Closing twice is harmless; any other use raises. Waits for a call
        in progress on another thread."""
        with self._one_call():
            if self._handle is not None:
                self._handle.close()
            self._handle = None
            self._obs = self._reward = self._terminated = self._truncated = self._info = self._final = None
            self._last_actions = None

    def __enter__(self) -> "VecEnv":
        return self

    def __reduce_ex__(self, protocol):  # pickle, copy.copy and copy.deepcopy alike: a copy would share the batch
        raise TypeError("a VecEnv holds the runtime's batch and cannot be pickled or copied: make another with "
                        "kage.make_vec and carry the state over with save_state() and load_state()")

    def __exit__(self, *exc) -> None:
        self.close()

    # ---- beyond Gymnasium ----

    def save_state(self) -> bytes:
        """The whole batch's state and last outputs (about 1.4 KB per environment); waits for queued
        work. ``load_state`` on a batch of the same config and size, on either device, continues
        exactly as this one would."""
        with self._one_call():
            return self._live().save_state()

    def load_state(self, state: bytes) -> Tuple[Any, Dict[str, Any]]:
        """Restores ``save_state``'s bytes and returns the restored (obs, info). ``state``: bytes or any
        bytes-like object (bytearray, memoryview, a uint8 numpy array; strided or read-only is fine)."""
        data = _state_bytes(state)
        with self._one_call():
            self._live().load_state(data)
            return self._returned((self._obs, self._info_dict()))

    def synchronize(self) -> None:
        """Waits for the batch's queued GPU work; raises ValueError if an earlier step had an
        out-of-range device action."""
        with self._one_call():
            self._live().synchronize()

    @property
    def stream(self) -> int:
        """The CUstream handle the batch queues its work on (0: the legacy default stream)."""
        return self._live().stream

    @property
    def unwrapped(self) -> "VecEnv":
        """This batch (Gymnasium's wrappers reach the environment through it)."""
        return self

    @property
    def resolved_spec(self) -> dict:
        """The resolved Spec the batch runs, as ``kagec resolve`` prints it (``{"config": {...}, "sha256": ...}``;
        Gymnasium's ``spec`` is another thing, an EnvSpec; a kagec compile directory's is its spec.json). Resolved
        on first use and checked against the batch's ``spec_hash``: a config file edited since ``make_vec`` raises
        instead of describing another game.
        A mixture runs several: see ``resolved_specs``."""
        if not isinstance(self.config, str):
            raise ValueError(f"this batch is a mixture of {len(self.configs)} configs, each with its own Spec: "
                             "resolved_specs lists them")
        if self._spec is None:
            if os.path.isdir(self.config):  # a kagec compile directory: the Spec it was compiled from
                with open(os.path.join(self.config, "spec.json")) as f:
                    spec = json.load(f)
            else:
                spec = front_end.resolve(self.config, self._asset_root)
            if spec["sha256"] != self.spec_hash:
                raise RuntimeError(f"{self.config} changed since this environment was made (spec "
                                   f"{self.spec_hash[:12]} then, {spec['sha256'][:12]} now): make the environment again")
            self._spec = spec
        return self._spec

    @property
    def resolved_specs(self) -> List[dict]:
        """The resolved Spec of each config, in order (one for a batch of one config), checked as
        ``resolved_spec`` is: a mixture's ``spec_hash`` is that of its configs' Specs and counts
        (``kage.front_end.mixture_hash``)."""
        if isinstance(self.config, str):
            return [self.resolved_spec]
        if self._specs is None:
            specs = [front_end.resolve(c, self._asset_root) for c in self.configs]
            now = front_end.mixture_hash([s["sha256"] for s in specs], self.counts)
            if now != self.spec_hash:
                raise RuntimeError(f"a config of this mixture changed since it was made (mixture {self.spec_hash[:12]} "
                                   f"then, {now[:12]} now): make the environment again")
            self._specs = specs
        return self._specs

    @property
    def closed(self) -> bool:
        return self._handle is None

    def __repr__(self) -> str:
        state = "closed" if self.closed else f"{self.num_envs} envs on {self.device}"
        return f"<kage.VecEnv {self.config!r}, {state}, spec {self.spec_hash[:12]}>"

    @contextlib.contextmanager
    def _one_call(self):
        """Holds the batch for one call. A call made from inside another on the same thread (an actions
        object whose __array__ or __dlpack__ calls back into the batch) would wait for itself forever: it raises."""
        if self._caller == threading.get_ident():
            raise RuntimeError("a call into this environment from inside another of its calls on the same thread "
                               "(an actions object calling back into the batch while it is read): call it afterwards")
        with self._lock:
            self._caller = threading.get_ident()
            try:
                yield
            finally:
                self._caller = None

    def _live(self) -> "kage._kage.Env":
        if self._handle is None:
            raise RuntimeError("this environment is closed: make a new one with kage.make_vec")
        return self._handle

    def _returned(self, outputs: tuple) -> tuple:
        """What reset, step and load_state return: the runtime's buffers, or under copy=True copies the caller
        owns (host arrays only: make_vec refuses copy=True on the GPU)."""
        if not self._copy:
            return outputs

        def owned(value):
            return {k: owned(v) for k, v in value.items()} if isinstance(value, dict) else value.copy()
        return tuple(owned(value) for value in outputs)

    def _info_dict(self) -> Dict[str, Any]:
        info = dict(self._info)
        info.update(self._final)
        return info


def make_vec(config: Union[str, os.PathLike, Sequence[Union[str, os.PathLike]]], num_envs: int, device: str = "cpu",
             seed: int = 0, asset_root: Optional[str] = None, threads: Optional[int] = None, stream=None,
             weights: Optional[Sequence[float]] = None, copy: bool = False) -> VecEnv:
    """A batch of ``num_envs`` environments of ``config`` (a YAML file or a ``kagec compile``
    directory) on ``device`` ("cpu" or "cuda").

    A list of YAML configs makes a mixture: one batch whose environments are split across the configs by
    ``weights`` (one non-negative number per config; default equal), each config's environments running its
    own kernels and writing their part of the one set of outputs; ``info["config"]`` gives each environment's
    config index (``kage.mixture`` says exactly how the batch is split). The configs must differ only on
    visual axes: one hidden game (physics, layout geometry, reward, episode length) and one observation shape,
    which kagec certifies first (a config that differs raises ``kage.ConfigError`` naming the first latent key,
    located, and both files). Environment i gets the seed it would get in a batch of one config
    (``env_seeds(seed, num_envs)[i]``), so each config's slice equals that config run alone with those
    seeds. A mixture runs on either device, from YAML configs; on the GPU each config's environments run
    that config's own kernels on their rows of the one set of device buffers (no copy).

    ``seed`` seeds ``reset()`` calls without a seed. ``asset_root`` resolves the config's asset paths
    (default: relative to the file that names them). ``threads``: CPU worker threads (default: one
    per core; results do not depend on it). ``stream``: GPU only, the CUDA stream the batch queues its
    work on (a ``torch.cuda.Stream``, or a CUstream handle); default the legacy default stream, which
    orders with PyTorch's default stream, so a learner on that stream needs no synchronisation. ``copy``: CPU
    only; True makes ``reset``, ``step`` and ``load_state`` return copies the caller owns (as Gymnasium's
    ``SyncVectorEnv(copy=True)``), for code that keeps the arrays it is given; the default returns the
    runtime's buffers, which the next step overwrites (no copy per step).

    Raises ``kage.ConfigError`` (with kagec's located diagnostics) for a config with errors,
    ``FileNotFoundError`` for a missing config, ``RuntimeError`` for ``device="cuda"`` without a usable
    GPU, ``ValueError`` for bad arguments and for a CPU batch that would need more than half of the
    machine's memory. The batch holds no episode until the first ``reset()`` (or ``load_state``): a step or a
    ``save_state`` before it raises ``RuntimeError`` (``outputs()`` shows zeros). Every argument is checked before anything is made. A YAML config's
    warnings (``kagec lint``'s: an inert setting, a reproduced quirk, ...) and the asset loader's are given as
    one ``kage.ConfigWarning``.
    """
    mixture = not isinstance(config, (str, bytes, os.PathLike))
    if mixture and not isinstance(config, (list, tuple)):
        raise TypeError(f"config={config!r:.80}: a path (str or os.PathLike) to a YAML config or a kagec compile "
                        "directory, or a shipped config's name; or a list of YAML configs (a mixture)")
    if weights is not None and not mixture:
        raise ValueError("weights= splits a mixture: give a list of configs")
    configs = _mixture.config_list(config) if mixture else [os.fsdecode(os.fspath(config))]
    if device not in ("cpu", "cuda"):
        raise ValueError(f"device={device!r}: use 'cpu' or 'cuda'")
    if not _is_integer(num_envs) or not 0 < num_envs <= MAX_INT32:
        raise ValueError(f"num_envs={num_envs!r}: a positive integer up to {MAX_INT32}")
    counts = (_mixture.split_warned(int(num_envs), _mixture.weights_of(weights, len(configs)), configs, "kage.make_vec")
              if mixture else None)
    seed = _seed_value(seed)
    if asset_root is not None:
        if not isinstance(asset_root, (str, bytes, os.PathLike)):
            raise ValueError(f"asset_root={asset_root!r:.80}: a directory path (str or os.PathLike)")
        asset_root = os.fsdecode(asset_root)
        if not os.path.isdir(asset_root):  # else a config without assets ignores it, one with assets blames the YAML
            raise FileNotFoundError(f"asset_root={asset_root!r}: no such directory; it replaces the config's own "
                                    "folder as the base of its relative asset paths: give that directory, or leave "
                                    "it out")
    # Paths, or shipped configs' names; FileNotFoundError names near ones.
    configs = [resources.config_path(c) for c in configs]
    if mixture:
        configs = _mixture.yaml_configs(configs)
    if threads is None:
        threads = min(int(num_envs), os.cpu_count() or 1)
    if not _is_integer(threads) or not 0 < threads <= MAX_INT32:
        raise ValueError(f"threads={threads!r}: a positive integer up to {MAX_INT32}")
    if device == "cpu" and stream is not None:
        raise ValueError("stream= is for device='cuda'")
    if not isinstance(copy, bool):
        raise ValueError(f"copy={copy!r}: True or False")
    if copy and device == "cuda":
        raise ValueError("copy=True copies host arrays: on the GPU, clone what you keep (torch.from_dlpack(obs)"
                         ".clone()), or leave copy out")
    stream_handle = 0 if stream is None else getattr(stream, "cuda_stream", stream)
    if not _is_integer(stream_handle) or not 0 <= stream_handle < 2**64:
        raise ValueError(f"stream={stream!r}: a torch.cuda.Stream or a CUstream handle (an integer)")
    if mixture:
        # kagec's certificate first: a refusal (ConfigError, one located line) before anything is made.
        front_end.certify_mixture(configs, asset_root)
        handle, config_warnings = native().open_mixture(configs, list(counts), device, int(threads),
                                                        asset_root or "", int(stream_handle))
    else:
        handle, config_warnings = native().open(configs[0], int(num_envs), device, int(threads), asset_root or "",
                                                int(stream_handle))
    if config_warnings:
        warnings.warn(ConfigWarning(config_warnings.rstrip()), stacklevel=2)
    return VecEnv(handle, configs if mixture else configs[0], seed, asset_root, counts, copy)


def step_batches(envs: Sequence[VecEnv], actions) -> None:
    """Steps ``envs[i]`` with ``actions[i]`` for every i, as ``envs[i].step(actions[i])`` would, in one call into
    the runtime: for a learner that steps many batches (a pack's runs, an evaluation's configs) every step, where
    one Python call per batch would cost more than the batches' kernels. ``actions``: [len(envs), num_envs]
    integers, host or GPU as ``step`` takes them; the batches must have one size. Read the outputs with
    ``outputs()``, the views ``step`` returns. Device actions step the GPU batches together: one step launch and
    one render launch per config over every batch (and mixture part) that runs it, on ``envs[0]``'s stream, the
    others' streams ordered before and after. What ``step`` would refuse before stepping (a shape, a dtype, a
    device), and a host action outside 0..7 in any row, is refused before any batch steps, naming the batch. A
    batch whose step fails (one never reset, or an out-of-range action reported by an earlier step of device
    actions) raises that error, naming the batch: with device actions no batch has stepped, with host actions
    the batches before it have."""
    envs = list(envs)
    if not envs or not all(isinstance(env, VecEnv) for env in envs):
        raise TypeError("step_batches: a non-empty list of kage.VecEnv (from kage.make_vec)")
    if len({id(env) for env in envs}) != len(envs):
        raise ValueError("step_batches: a batch appears twice: step each batch once per call")
    with contextlib.ExitStack() as held:
        for env in sorted(envs, key=id):  # one order for every caller: two calls on other threads never deadlock
            held.enter_context(env._one_call())
        _actions.submit_rows([env._live() for env in envs], actions)
        for env in envs:  # the runtime reads device actions when its kernels run
            env._last_actions = actions
