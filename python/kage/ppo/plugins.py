"""The trainer's plug-in points: the policy network (--agent module:factory) and the augmentation of
training batches (--augment module:fn), each named as an importable `module:attribute`.

An agent factory is called as factory(observation_shape, num_actions, seeds, device), observation_shape
being (H, W, C) of uint8 frames (C = 12 under --use-frame-stack), and returns a torch.nn.Module:
- a packable factory (`factory.packable = True`, as kage.ppo.agent.nature_cnn) gets the seeds of the K runs of
  a pack and returns one network for all of them: forward(uint8 [K, B, H, W, C]) -> (logits [K, B, A],
  values [K, B]), and run_view(tensor) splitting a parameter-shaped tensor into [K, ...] (each run's part);
  one that sets `takes_frame_indices = True` (as kage.ppo.agent.Agent) is also called as forward(frames,
  images) on update minibatches: run k's b-th frame is frames.reshape(-1, H, W, C)[images[k, b]], frames
  being the rollout buffer, so it may read them there instead of in a gathered copy;
- any other factory gets one seed and returns a plain network: forward(uint8 [B, H, W, C]) -> (logits
  [B, A], values [B]). Its runs train one at a time (kage.bench run --pack falls back to lone runs).
The global torch seed is the run's seed when the factory is called, so its initialisation is reproducible.

An augmentation is called as fn(obs, uniform) on every update minibatch (never on the rollout's or an
evaluation's observations): obs is uint8 [K, B, H, W, C], uniform(shape) returns [K, *shape] float32
uniforms in (0, 1) from each run's own counter-based stream (the same numbers alone, packed or resumed);
it returns uint8 frames of the same shape.
"""
import difflib
import importlib
import inspect
from typing import Callable, List, Optional, Sequence

import torch
import torch.nn as nn

from kage.ppo.policy import autocast

BASELINE_AGENT = "kage.ppo.agent:nature_cnn"
# Modules of the package that moved: references written before (command lines, run.json) still name them.
MOVED_MODULES = {"kage.agent": "kage.ppo.agent", "kage.augment": "kage.ppo.augment"}


def current_reference(reference: Optional[str]) -> Optional[str]:
    """`reference` with a moved module's old name replaced by its new one."""
    if reference is None:
        return None
    module_name, colon, attribute = reference.partition(":")
    return MOVED_MODULES.get(module_name, module_name) + colon + attribute


def load(reference: str, flag: str) -> Callable:
    """The callable named by `module:attribute`, or a SystemExit naming the flag and the fix."""
    module_name, _, attribute = current_reference(reference).partition(":")
    if not module_name or not attribute:
        raise SystemExit(f"kage.ppo.train: {flag} {reference!r}: write it as module:attribute (e.g. {BASELINE_AGENT})")
    try:
        module = importlib.import_module(module_name)
    except ImportError as e:
        raise SystemExit(f"kage.ppo.train: {flag} {reference}: cannot import '{module_name}' ({e}); put the directory "
                         "that holds it on PYTHONPATH") from None
    found = getattr(module, attribute, None)
    if not callable(found):
        names = [n for n, v in vars(module).items() if callable(v) and not n.startswith("_")
                 and getattr(v, "__module__", None) == module.__name__]
        what = "has no" if found is None else "has a non-callable"
        close = difflib.get_close_matches(attribute, names, n=1)
        hint = f"did you mean '{close[0]}'?" if close else f"it defines {', '.join(names) or 'no functions'}"
        raise SystemExit(f"kage.ppo.train: {flag} {reference}: {module.__file__} {what} '{attribute}'; {hint}")
    return found


def is_packable(factory: Callable) -> bool:
    return getattr(factory, "packable", False) is True


class LoneRun(nn.Module):
    """A plain (one-run) network in the trainer's pack interface, K = 1."""

    runs = 1

    def __init__(self, net: nn.Module):
        super().__init__()
        self.net = net

    def forward(self, obs: torch.Tensor):
        logits, value = self.net(obs[0])
        return logits[None], value[None]

    def run_view(self, tensor: torch.Tensor) -> torch.Tensor:
        return tensor.unsqueeze(0)


def build_agent(reference: str, observation_shape: Sequence[int], num_actions: int, seeds: List[int],
                device, speed: Optional[dict] = None) -> nn.Module:
    """The network of `reference` for the runs of `seeds`, in the pack interface, checked on a batch of
    two blank frames so that a wrong output shape is reported here, with what was expected. `speed`: keyword
    arguments for the baseline's factory (its speed modes, kage.ppo.agent.Agent); other factories get none."""
    factory = load(reference, "--agent")
    packable = is_packable(factory)
    if len(seeds) > 1 and not packable:
        raise SystemExit(f"kage.ppo.train: --agent {reference} is not packable (its factory has no `packable = True`): "
                         "train its runs one at a time (kage.bench run does so by itself)")
    torch.manual_seed(seeds[0])
    net = factory(tuple(observation_shape), num_actions, list(seeds) if packable else seeds[:1], device, **(speed or {}))
    if not isinstance(net, nn.Module):
        raise SystemExit(f"kage.ppo.train: --agent {reference} returned {type(net).__name__}, not a torch.nn.Module")
    if packable and not callable(getattr(net, "run_view", None)):
        raise SystemExit(f"kage.ppo.train: --agent {reference} is packable but its network has no run_view(tensor) "
                         "(see kage.ppo.agent.Agent.run_view)")
    agent = net if packable else LoneRun(net)
    K = len(seeds)
    blank = torch.zeros((K, 2, *observation_shape), dtype=torch.uint8, device=device)
    with torch.no_grad(), autocast(bool(speed and speed.get("bf16"))):  # as the trainer calls it
        logits, value = agent(blank)
    if tuple(logits.shape) != (K, 2, num_actions) or tuple(value.shape) != (K, 2):
        shape = "[K, B, H, W, C] -> [K, B, A], [K, B]" if packable else "[B, H, W, C] -> [B, A], [B]"
        got = (logits.shape, value.shape) if packable else (logits.shape[1:], value.shape[1:])
        raise SystemExit(f"kage.ppo.train: --agent {reference}: the network must map {shape} (A = {num_actions} "
                         f"actions); on a batch of 2 it returned logits {list(got[0])} and values {list(got[1])}")
    return agent


def load_augment(reference: Optional[str]) -> Optional[Callable]:
    """The --augment function, checked to take (obs, uniform)."""
    if not reference:
        return None
    fn = load(reference, "--augment")
    try:
        inspect.signature(fn).bind(None, None)
    except TypeError:
        raise SystemExit(f"kage.ppo.train: --augment {reference}: the function must take (obs, uniform); it takes "
                         f"{inspect.signature(fn)}") from None
    except ValueError:  # a builtin without a signature: trust it
        pass
    return fn


def augment_draws(random, stream: int, counter: torch.Tensor, optimizer_steps: int) -> Callable:
    """The uniform(shape) an augmentation draws from on one minibatch: each run's `stream` of `random` (a
    kage.ppo.counter_random.CounterRandom), the counter naming the optimiser step and the draw, so a run draws
    the same numbers alone, packed or resumed."""
    draws = 0

    def uniform(shape):
        nonlocal draws
        draws += 1
        return random.uniform(stream, counter.fill_(optimizer_steps * 64 + draws), shape)
    return uniform
