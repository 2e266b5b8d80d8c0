"""Registers KAGE with Gymnasium (done by ``import kage`` where Gymnasium is importable):

    gymnasium.make_vec("kage/KAGE-v0", num_envs=N, vectorization_mode="vector_entry_point", config=..., device=...)
    gymnasium.make("kage/KAGE-v0", config=...)

The first returns ``kage.make_vec``'s vector environment; the second ``kage.single_env.SingleEnv``, a view of a
batch of one."""
import importlib.util
from typing import Optional

ENV_ID = "kage/KAGE-v0"
CONFIG_TEXT = "config= names the game: a YAML file, a kagec compile directory or a shipped config's name"


def missing_config(call: str) -> TypeError:
    """The error for a make without config=, showing the call with one."""
    return TypeError(f"{ENV_ID}: {CONFIG_TEXT}, e.g. {call}")


def make_vector(num_envs: int, config: Optional[str] = None, device: str = "cpu", render_mode: Optional[str] = None,
                **kwargs):
    """Gymnasium's vector entry point: ``kage.make_vec(config, num_envs, device=device, **kwargs)``. The batch
    renders no frames of its own (its observations are the frames): a ``render_mode`` is refused."""
    from kage.vector import make_vec

    if config is None:
        raise missing_config(f"gymnasium.make_vec({ENV_ID!r}, num_envs={num_envs!r}, "
                             "vectorization_mode='vector_entry_point', config='throughput/simplest')")
    if render_mode is not None:
        raise ValueError(f"render_mode={render_mode!r}: {ENV_ID}'s vector environment renders no frames of its own; "
                         "its observations are the frames (leave render_mode out), or gymnasium.make one environment "
                         "with render_mode='rgb_array'")
    return make_vec(config, num_envs, device=device, **kwargs)


def register_with_gymnasium() -> bool:
    """Registers ENV_ID where Gymnasium is importable (once); whether it is."""
    if importlib.util.find_spec("gymnasium") is None:
        return False
    import gymnasium

    if ENV_ID not in gymnasium.registry:
        gymnasium.register(id=ENV_ID, entry_point="kage.single_env:SingleEnv",
                           vector_entry_point="kage.registration:make_vector")
    return True
