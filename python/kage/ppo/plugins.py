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

An augmentation is called as fn(obs, uniform) on training frames, as --augment-mode says (kage.ppo.train):
the update's minibatches (drac, update) or the rollout's observations (rollout), never an evaluation's.
obs is uint8 [K, B, H, W, C], uniform(shape) returns [K, *shape] float32 uniforms in (0, 1) from each run's own
counter-based stream (the same numbers alone, packed or resumed); it returns uint8 frames of the same shape on
the same device (checked on blank frames before anything is written, and on every call; drawing from a global
random generator instead of `uniform` is warned of there, as its runs would not reproduce). One that sets
`fn.takes_frame_indices = True` (as kage.ppo.augment's) is called on update minibatches as fn(frames, uniform,
images=images), run k's b-th frame being frames.reshape(-1, H, W, C)[images[k, b]], so it may read them where
the rollout stored them.
"""
import difflib
import importlib
import inspect
import random as python_random  # `random` names a run's CounterRandom here
from typing import Callable, List, Optional, Sequence

import numpy as np
import torch
import torch.nn as nn

from kage.ppo.counter_random import CounterRandom
from kage.ppo.policy import autocast

BASELINE_AGENT = "kage.ppo.agent:nature_cnn"
EXAMPLES = {"--agent": BASELINE_AGENT, "--augment": "kage.ppo.augment:random_shift"}  # each flag's own kind
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
    example = EXAMPLES.get(flag, BASELINE_AGENT)
    if not module_name.strip() or not attribute.strip():
        raise SystemExit(f"kage.ppo.train: {flag} {reference!r}: write it as module:attribute (e.g. {example})")
    if module_name.endswith(".py") or "/" in module_name:
        stem = module_name.rsplit("/", 1)[-1].removesuffix(".py")
        raise SystemExit(f"kage.ppo.train: {flag} {reference}: name a module, not a file: {stem}:{attribute}, with the "
                         "directory that holds it on PYTHONPATH")
    try:
        module = importlib.import_module(module_name)
    except ImportError as e:
        if e.name and not (module_name + ".").startswith(e.name + "."):  # found, but a module it imports is not
            raise SystemExit(f"kage.ppo.train: {flag} {reference}: importing '{module_name}' failed: {e}; install "
                             "what it imports, or fix the import") from None
        raise SystemExit(f"kage.ppo.train: {flag} {reference}: cannot import '{module_name}' ({e}); put the directory "
                         "that holds it on PYTHONPATH") from None
    except Exception as e:  # a user's module: whatever its import raises is reported as its failure
        where = f" ({e.filename}, line {e.lineno})" if isinstance(e, SyntaxError) else ""
        raise SystemExit(f"kage.ppo.train: {flag} {reference}: importing '{module_name}' raised "
                         f"{type(e).__name__}: {e}{where}; fix the module") from None
    found = getattr(module, attribute, None)
    if not callable(found):
        names = list(getattr(module, "__all__", None) or  # the module's own list of what it offers, else its functions
                     [n for n, v in vars(module).items() if callable(v) and not n.startswith("_")
                      and getattr(v, "__module__", None) == module.__name__])
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
    try:
        net = factory(tuple(observation_shape), num_actions, list(seeds) if packable else seeds[:1], device,
                      **(speed or {}))
    except Exception as e:  # a user's factory: whatever it raises is reported as its failure
        raise SystemExit(f"kage.ppo.train: --agent {reference}: calling it as factory(observation_shape, num_actions, "
                         f"seeds, device) raised {type(e).__name__}: {e}; it must build the network "
                         "(kage.ppo.plugins)") from None
    if not isinstance(net, nn.Module):
        raise SystemExit(f"kage.ppo.train: --agent {reference} returned {type(net).__name__}, not a torch.nn.Module")
    if not any(p.requires_grad for p in net.parameters()):
        raise SystemExit(f"kage.ppo.train: --agent {reference} built a network without trainable parameters: PPO "
                         "has nothing to train")
    if packable and not callable(getattr(net, "run_view", None)):
        raise SystemExit(f"kage.ppo.train: --agent {reference} is packable but its network has no run_view(tensor) "
                         "(see kage.ppo.agent.Agent.run_view)")
    agent = net if packable else LoneRun(net)
    K = len(seeds)
    blank = torch.zeros((K, 2, *observation_shape), dtype=torch.uint8, device=device)
    try:
        with torch.no_grad(), autocast(bool(speed and speed.get("bf16"))):  # as the trainer calls it
            output = agent(blank)
        logits, value = output
    except Exception as e:
        raise SystemExit(f"kage.ppo.train: --agent {reference}: its network on a blank batch of uint8 frames "
                         f"{list(blank.shape)} raised {type(e).__name__}: {e}") from None
    if not (torch.is_tensor(logits) and torch.is_tensor(value)) or tuple(logits.shape) != (K, 2, num_actions) or \
            tuple(value.shape) != (K, 2) or not (logits.is_floating_point() and value.is_floating_point()):
        shape = "[K, B, H, W, C] -> [K, B, A], [K, B]" if packable else "[B, H, W, C] -> [B, A], [B]"
        described = [describe(t, 0 if packable else 1) for t in (logits, value)]
        raise SystemExit(f"kage.ppo.train: --agent {reference}: the network must map {shape} (A = {num_actions} "
                         f"actions, floating point); on a batch of 2 it returned logits {described[0]} and values "
                         f"{described[1]}")
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


def describe(value, lead: int) -> str:
    """A network output as an error message shows it: a tensor's shape and dtype past `lead` axes, else its type."""
    if not torch.is_tensor(value):
        return type(value).__name__
    return f"{list(value.shape[lead:])} {str(value.dtype).replace('torch.', '')}"


def augment_draws(random, stream: int, counter: torch.Tensor, position: int) -> Callable:
    """The uniform(shape) an augmentation draws from on one batch: each run's `stream` of `random` (a
    kage.ppo.counter_random.CounterRandom), the counter naming the batch's position (the optimiser step of an
    update minibatch, the step of a rollout) and the draw, so a run draws the same numbers alone, packed or
    resumed."""
    draws = 0

    def uniform(shape):
        nonlocal draws
        draws += 1
        return random.uniform(stream, counter.fill_(position * 64 + draws), shape)
    return uniform


def augment_frames(fn: Callable, reference: str, frames: torch.Tensor, uniform: Callable,
                   images: Optional[torch.Tensor] = None) -> torch.Tensor:
    """fn on `frames` (at `images` where given: see the contract above), its output checked: uint8 frames of the
    input's shape on its device. Outside any autocast (a truncation's bootstrap runs under --bf16's), so that its
    parameters are the same float32 numbers wherever it is called."""
    at_indices = images is not None and getattr(fn, "takes_frame_indices", False) is True
    with torch.autocast(frames.device.type, enabled=False):
        try:
            if at_indices:
                out = fn(frames, uniform, images=images)
                expected = (*images.shape, *frames.shape[-3:])
            else:
                frames = frames if images is None else frames.reshape(-1, *frames.shape[-3:])[images]
                out = fn(frames, uniform)
                expected = tuple(frames.shape)
        except (Exception, SystemExit) as e:  # a user's function: whatever it raises is reported as its failure
            raise SystemExit(f"kage.ppo.train: --augment {reference}: on uint8 frames {list(frames.shape)}"
                             f"{f' at images {list(images.shape)}' if at_indices else ''} it raised "
                             f"{type(e).__name__}: {e}") from None
    problem = augmented_problem(out, expected, frames.device)
    if problem:
        contract = (" (called with images=, run k's b-th frame is frames.reshape(-1, H, W, C)[images[k, b]]: it "
                    "returns one frame per index)") if at_indices else ""
        raise SystemExit(f"kage.ppo.train: --augment {reference}: {problem}{contract}")
    if out is not frames and out.untyped_storage().data_ptr() == frames.untyped_storage().data_ptr():
        out = out.clone()  # a view of its input (a transpose, a slice): its own memory, for the copy into the rollout
    return out


def augmented_problem(out, shape, device) -> Optional[str]:
    """What is wrong with an augmentation's output, or None."""
    expected = f"uint8 frames {list(shape)} on {device}"
    if not torch.is_tensor(out):
        return f"returned {type(out).__name__}, not {expected}"
    if out.dtype != torch.uint8:
        return (f"returned {str(out.dtype).replace('torch.', '')} frames; it must return {expected} (values 0-255, "
                "as it was given them: the network divides by 255 itself)")
    if tuple(out.shape) != tuple(shape):
        return f"returned frames {list(out.shape)}; it must return {expected}"
    if out.device != torch.device(device):
        return f"returned frames on {out.device}; it must return {expected}"
    return None


def global_generators(device) -> dict:
    """The states of the global random generators an augmentation could draw from instead of `uniform`."""
    states = {"torch's": torch.get_rng_state(), "numpy's": np.random.get_state(), "Python's": python_random.getstate()}
    if torch.device(device).type == "cuda":
        states["torch.cuda's"] = torch.cuda.get_rng_state(device)
    return states


def same_state(a, b) -> bool:
    """Whether two states of global_generators' (tensors, numpy's tuple with its key array, Python's tuples) match."""
    if torch.is_tensor(a):
        return torch.equal(a, b)
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(same_state(x, y) for x, y in zip(a, b))
    if hasattr(a, "shape"):  # numpy's key array
        return bool((a == b).all())
    return a == b


def check_augment(fn: Callable, reference: str, shape, device) -> Optional[str]:
    """Calls the augmentation once on blank uint8 frames of the real shape (K runs of 2 frames), alone and, where it
    reads frames at indices, at indices, so that a wrong output is refused before anything is written. Returns a
    warning when the calls drew from a global random generator (torch's, numpy's, Python's): such draws are the
    process's, not the run's, so a resumed or packed run draws other numbers than the same run uninterrupted or
    alone."""
    before = global_generators(device)
    random = CounterRandom([0] * shape[0], device)
    counter = torch.zeros((), dtype=torch.int64, device=device)
    blank = torch.zeros(shape, dtype=torch.uint8, device=device)
    # One index more per run than frames per run, so that a function that ignores `images` returns the wrong shape.
    images = torch.arange(shape[0] * (shape[1] + 1), device=device).remainder(shape[0] * shape[1])
    for at in (None, images.view(shape[0], shape[1] + 1)):
        augment_frames(fn, reference, blank, augment_draws(random, 0, counter, 0), at)
    after = global_generators(device)
    drawn = [name for name in before if not same_state(before[name], after[name])]
    if not drawn:
        return None
    return (f"--augment {reference} draws from {' and '.join(drawn)} global random generator: those numbers are the "
            "process's, not the run's, so the run will not reproduce when resumed, packed with others or run alone; "
            "draw from its `uniform(shape)` argument instead (each run's own stream, kage.ppo.plugins)")
