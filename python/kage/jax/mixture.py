"""kage.jax.make_env, and the mixture of kage.jax: one batch over several configs (kage.mixture's split and
certification, as kage.make_vec's mixture), as the two pure functions of a JaxEnv.

Each config's environments are their own JaxEnv (its FFI calls, its specialised kernels on the GPU), stepped
on its slice of the actions; the outputs are the parts' outputs concatenated along the environment axis. XLA
owns each FFI call's result buffers, so the frames are copied once into the whole batch's array (one copy of
N x H x W x 3 bytes per step, inside the jitted program); everything else equals make_vec's mixture byte for
byte, seeds included (environment i gets ``kage.env_seeds(seed, num_envs)[i]``).
"""
import dataclasses
import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import jax
import jax.numpy as jnp
import numpy as np

from kage import front_end, mixture, resources, vector
from kage.jax.env import JaxEnv, KageState, check_action_record, checked_actions, make_config_env, seed_words

_FINAL_KEYS = ("_final", "_final_obs", "_final_info")


@dataclasses.dataclass(frozen=True)
class MixtureState:
    """The state of a mixture: the KageState of each config that has environments, in config order. Its
    ``spec_hash`` (the mixture's, static) is refused by another mixture."""

    parts: Tuple[KageState, ...]
    spec_hash: str


jax.tree_util.register_dataclass(MixtureState, data_fields=["parts"], meta_fields=["spec_hash"])


class JaxMixture:
    """``num_envs`` environments split across configs that differ only on visual axes, as two pure functions
    with JaxEnv's signatures: ``reset(seed) -> (state, obs, info)`` and ``step(state, actions) -> (state, obs,
    reward, terminated, truncated, info)``, outputs as make_vec's mixture gives them (``info["config"]``: each
    environment's config index)."""

    metadata = {"autoreset_mode": "same-step"}

    def __init__(self, configs: List[str], counts: Tuple[int, ...], parts: List[JaxEnv], spec_hash: str):
        self.config = list(configs)
        self.configs = tuple(configs)
        self.counts = counts
        self.num_envs = sum(counts)
        self.spec_hash = spec_hash
        self.parts = parts  # the JaxEnv of each config with environments, in config order
        self.single_observation_space = parts[0].single_observation_space
        self.single_action_space = parts[0].single_action_space
        self._config_index = mixture.config_index(counts)
        starts = np.cumsum((0,) + tuple(p.num_envs for p in parts))
        self._slices = [slice(int(a), int(b)) for a, b in zip(starts[:-1], starts[1:])]

    def reset(self, seed) -> Tuple[MixtureState, Any, Dict[str, Any]]:
        """Starts episode 0 of every environment; environment i gets ``kage.env_seeds(seed, num_envs)[i]``, as in
        make_vec's mixture. ``seed``: a non-negative int, or a uint32 JAX scalar (traced or not)."""
        words = seed_words(seed, self.num_envs)
        results = [part._reset_words(words[s]) for part, s in zip(self.parts, self._slices)]
        state = MixtureState(tuple(r[0] for r in results), self.spec_hash)
        return state, self._joined([r[1] for r in results]), self._info([r[2] for r in results])

    def step(self, state: MixtureState, actions) -> Tuple[MixtureState, Any, Any, Any, Any, Dict[str, Any]]:
        """One step of every environment with ``actions``, int32 [num_envs]: each config's slice goes to its part
        (values outside 0..7 are recorded as JaxEnv records them)."""
        self._check_state(state)
        actions = checked_actions(actions, self.num_envs)
        results = [part.step(s, actions[sl]) for part, s, sl in zip(self.parts, state.parts, self._slices)]
        new = MixtureState(tuple(r[0] for r in results), self.spec_hash)
        obs, reward, terminated, truncated = (self._joined([r[i] for r in results]) for i in range(1, 5))
        return new, obs, reward, terminated, truncated, self._info([r[5] for r in results])

    def check(self, state: MixtureState) -> None:
        """Raises ValueError naming the first action outside 0..7 since the reset (its environment numbered in the
        whole batch); outside ``jit``, as JaxEnv.check."""
        self._check_state(state, batched=True)
        for part, s in zip(self.parts, state.parts):
            part._check_state(s, batched=True)
        check_action_record(jnp.concatenate([s.action_error for s in state.parts], axis=-2))

    def __repr__(self) -> str:
        return (f"<kage.jax.JaxMixture of {len(self.configs)} configs {list(self.counts)}, {self.num_envs} envs, "
                f"spec {self.spec_hash[:12]}>")

    def _check_state(self, state, batched: bool = False) -> None:
        if not isinstance(state, MixtureState):
            raise TypeError(f"state: expected the MixtureState that this mixture's reset or step returned, got "
                            f"{type(state).__name__}")
        if state.spec_hash != self.spec_hash or len(state.parts) != len(self.parts):
            raise ValueError(f"state: it belongs to the mixture with spec hash {state.spec_hash[:16]}..., but this "
                             f"environment runs {self.spec_hash[:16]}...: give each environment the state its own "
                             "reset returned")

    @staticmethod
    def _joined(arrays):
        """The parts' arrays as the whole batch's, along the environment axis (a copy; none for one part)."""
        return arrays[0] if len(arrays) == 1 else jnp.concatenate(arrays, axis=0)

    def _info(self, infos: List[Dict[str, Any]]) -> Dict[str, Any]:
        """The parts' info joined; the batch's field `config` is the mixture's index (a constant of the graph)."""
        names = [n for n in infos[0] if n not in ("final_obs", "final_info") + _FINAL_KEYS]
        config = jnp.asarray(self._config_index)
        info = {n: self._joined([i[n] for i in infos]) for n in names}
        info["config"] = config
        final_info = {n: self._joined([i["final_info"][n] for i in infos]) for n in infos[0]["final_info"]}
        final_info["config"] = config
        final = self._joined([i["_final"] for i in infos])
        info.update(final_obs=self._joined([i["final_obs"] for i in infos]), final_info=final_info)
        info.update({k: final for k in _FINAL_KEYS})
        return info


def make_env(config: Union[str, os.PathLike, Sequence[Union[str, os.PathLike]]], num_envs: int, asset_root=None,
             weights: Optional[Sequence[float]] = None) -> Union[JaxEnv, JaxMixture]:
    """``num_envs`` environments of ``config`` (a YAML file or a ``kagec compile`` directory) for JAX; or, for a
    list of YAML configs, a mixture (a JaxMixture) split by ``weights`` as ``kage.make_vec``'s (kage.mixture).

    Raises what ``kage.make_vec`` raises for the same config: ``kage.ConfigError`` with kagec's located
    diagnostics (for a mixture, also when its configs differ on a latent key or in observation shape),
    ``FileNotFoundError``, ``ValueError`` for bad arguments. ``asset_root`` as make_vec's.
    ``num_envs`` has make_vec's limits: at most 2**31 - 1, and no more environments than make_vec builds on
    the CPU (their states, observations and render scratch within half of the machine's memory), on every
    backend; beyond them it raises ValueError with make_vec's words before anything is allocated.
    """
    if isinstance(config, (str, bytes, os.PathLike)):
        if weights is not None:
            raise ValueError("weights= splits a mixture: give a list of configs")
        return make_config_env(config, num_envs, asset_root)
    if not isinstance(config, (list, tuple)):
        raise TypeError(f"config={config!r:.80}: a path to a YAML config or a kagec compile directory, or a list "
                        "of YAML configs (a mixture)")
    configs = mixture.config_list(config)
    if not vector._is_integer(num_envs) or not 0 < num_envs <= vector.MAX_INT32:
        raise ValueError(f"num_envs={num_envs!r}: a positive integer up to {vector.MAX_INT32}")
    counts = mixture.split_warned(int(num_envs), mixture.weights_of(weights, len(configs)), configs, "kage.jax.make_env")
    paths = mixture.yaml_configs([resources.config_path(c) for c in configs])
    certificate = front_end.certify_mixture(paths, os.fspath(asset_root) if asset_root else None)
    spec_hash = front_end.mixture_hash([c["spec_sha256"] for c in certificate["configs"]], counts)
    parts = [make_config_env(path, n, asset_root) for path, n in zip(paths, counts) if n > 0]
    return JaxMixture(paths, counts, parts, spec_hash)
