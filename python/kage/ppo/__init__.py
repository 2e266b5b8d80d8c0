"""The PPO-CNN baseline of KAGE-Bench (kage-ppo-baseline.md): the trainer (`python3 -m kage.ppo.train`), the
network, the evaluation protocol, the checkpoint scorer (`python3 -m kage.ppo.evaluate`), videos, the run directory,
plug-ins, augmentations and wrappers. Built on the environment API (kage); knows nothing of the benchmark runner."""
