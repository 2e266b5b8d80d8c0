"""One KAGE environment with Gymnasium's single-environment API, for ``gymnasium.make("kage/KAGE-v0",
config=...)``: a view of a batch of one (``kage.make_vec(config, 1)``) that copies what it returns, so the
arrays stay valid after the next step, as Gymnasium's checks expect.

Episode ends: the runtime resets an environment in the step that ends its episode (same-step autoreset).
This view hides that: the step that ends an episode returns that episode's last observation and info, with
``terminated`` or ``truncated`` true, as Gymnasium's API says. Then ``reset()`` without a seed returns the
first observation of the episode the runtime already started in that step (its randomness comes from the
environment's own seed stream, as in ``kage.make_vec``); ``reset(seed=s)`` starts afresh from ``s``.
Stepping on after an episode's end without ``reset()`` continues that new episode.

Seeds as Gymnasium's: ``reset()`` anywhere else (the first reset, or in the middle of an episode, as a
``TimeLimit`` wrapper's truncation leaves it) starts a new episode from a seed drawn from ``self.np_random``,
which Gymnasium seeds from the operating system's entropy until a ``reset(seed=s)`` seeds it from ``s``: unseeded
environments differ from one another, and a seeded one repeats its episodes.
"""
from typing import Any, Dict, Optional, Tuple

import gymnasium
import numpy as np

from kage.registration import ENV_ID, missing_config
from kage.vector import make_vec


class SingleEnv(gymnasium.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 60}  # a step is dt = 1/60 s of game time (spec)

    def __init__(self, config: Optional[str] = None, device: str = "cpu", render_mode: Optional[str] = "rgb_array",
                 asset_root: Optional[str] = None):
        if config is None:
            raise missing_config(f"gymnasium.make({ENV_ID!r}, config='throughput/simplest')")
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode={render_mode!r}: KAGE renders 'rgb_array' frames only")
        self.render_mode = render_mode
        self._batch = make_vec(config, 1, device=device, asset_root=asset_root, threads=1)
        self.observation_space = self._batch.single_observation_space
        self.action_space = self._batch.single_action_space
        self._frame: Optional[np.ndarray] = None
        self._episode_ended = False  # the last step ended an episode: the runtime has started the next one

    def reset(self, *, seed: Optional[int] = None, options: Optional[Dict[str, Any]] = None
              ) -> Tuple[np.ndarray, Dict[str, Any]]:
        self._live()
        super().reset(seed=seed)
        if options:
            raise ValueError(f"reset: unknown options {sorted(options)} (a single environment takes none)")
        if seed is None and self._episode_ended:
            # The runtime started the next episode in the step that ended the last one: return its start.
            obs, _, _, _, info = self._batch.outputs()
        else:
            obs, info = self._batch.reset(seed=seed if seed is not None else int(self.np_random.integers(2**63)))
        self._episode_ended = False
        return self._keep(obs[0]), _row(info)

    def step(self, action) -> Tuple[np.ndarray, float, bool, bool, Dict[str, Any]]:
        self._live()
        if not self.action_space.contains(action):
            raise ValueError(f"action {action!r}: an integer in 0..{self.action_space.n - 1}")
        obs, reward, terminated, truncated, info = self._batch.step(np.array([action], dtype=np.int32))
        self._episode_ended = bool(np.asarray(info["_final"])[0])
        if self._episode_ended:  # show the episode's end, not the next start
            obs, fields = info["final_obs"], info["final_info"]
        else:
            fields = info
        return (self._keep(obs[0]), float(reward[0]), bool(terminated[0]), bool(truncated[0]), _row(fields))

    def render(self) -> Optional[np.ndarray]:
        """The last observation returned, [H, W, 3] uint8 (render_mode "rgb_array"), or None."""
        self._live()
        return None if self.render_mode is None or self._frame is None else self._frame.copy()

    def close(self) -> None:
        self._batch.close()

    def _live(self) -> None:
        if self._batch.closed:  # the batch's own message would name kage.make_vec, not how this one was made
            raise RuntimeError(f"this environment is closed: make a new one with gymnasium.make({ENV_ID!r}, "
                               "config=...)")

    def _keep(self, frame) -> np.ndarray:
        self._frame = np.array(frame, copy=True)
        return self._frame.copy()


def _row(info: Dict[str, Any]) -> Dict[str, Any]:
    """Row 0 of a batch's info fields, as Python scalars."""
    from kage.vector import INFO_NAMES

    return {name: np.asarray(info[name])[0].item() for name in INFO_NAMES}
