"""kage: KAGE-Env batches for Python, on the CPU or the GPU, without copies between the runtime and
the learner. See ``make_vec`` and ``VecEnv``; ``python3 -m kage.train`` trains the PPO-CNN baseline and
``python3 -m kage.bench`` runs and reports the benchmark."""
from kage._kage import DeviceArray, gpu_backend_built
from kage.errors import ConfigError, Diagnostic, DeviceUnavailableError
from kage.vector import INFO_FIELDS, VecEnv, env_seeds, make_vec

__all__ = [
    "ConfigError",
    "DeviceArray",
    "DeviceUnavailableError",
    "Diagnostic",
    "INFO_FIELDS",
    "VecEnv",
    "env_seeds",
    "gpu_backend_built",
    "make_vec",
]
