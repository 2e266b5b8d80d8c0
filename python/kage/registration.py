"""Registers KAGE with Gymnasium (done by ``import kage`` where Gymnasium is importable):

    gymnasium.make_vec("kage/KAGE-v0", num_envs=N, vectorization_mode="vector_entry_point", config=..., device=...)
    gymnasium.make("kage/KAGE-v0", config=...)

The first returns ``kage.make_vec``'s vector environment; the second ``kage.single_env.SingleEnv``, a view of a
batch of one."""
import importlib.util

ENV_ID = "kage/KAGE-v0"


def make_vector(num_envs: int, config: str, device: str = "cpu", **kwargs):
    """Gymnasium's vector entry point: ``kage.make_vec(config, num_envs, device=device, **kwargs)``."""
    from kage.vector import make_vec

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
