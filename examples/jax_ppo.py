"""PPO on kage.jax in the PureJaxRL style: the whole training iteration (the rollout as a lax.scan over
env.step, GAE as a reverse scan, epochs x minibatches as nested scans) is one jax.jit, vmapped over seeds so
that several agents train as one program. Network, initialisation, hyperparameters and loss are the
KAGE-Bench PPO-CNN baseline's (../shared/spec/kage-ppo-baseline.md; its section numbers are in the
comments). Plain JAX: the Nature CNN and Adam are written out below.

    python examples/jax_ppo.py --config configs/kage_bench/bases/shape_black.yaml --num-seeds 8

Prints one JSON line per iteration: the steps per agent, steps/s over all agents, and per agent the
episodes that ended in the iteration with their mean train success_once and return, and the losses of the
last minibatch (spec 2.5.5).
"""
import argparse
import dataclasses
import json
import time

import jax
import jax.numpy as jnp
import numpy as np

import kage.jax


@dataclasses.dataclass
class Args:
    config: str = "configs/kage_bench/bases/shape_black.yaml"
    """the environment config (a YAML file or a kagec compile directory)"""
    seed: int = 1
    """the first agent's seed; agent i has seed + i (its network, its actions, its levels)"""
    num_seeds: int = 1
    """agents trained together, vmapped"""
    total_timesteps: int = 25_000_000
    """environment steps per agent"""
    learning_rate: float = 5e-4
    num_envs: int = 128
    num_steps: int = 128
    gamma: float = 0.999
    gae_lambda: float = 0.95
    num_minibatches: int = 8
    update_epochs: int = 3
    norm_adv: bool = True
    clip_coef: float = 0.2
    clip_vloss: bool = True
    ent_coef: float = 0.01
    vf_coef: float = 0.5
    max_grad_norm: float = 0.5
    adam_eps: float = 1e-5


def boolean(text: str) -> bool:
    """A flag's true or false, as written; anything else (a misspelt `flase`) refused, not read as false."""
    if text.lower() in ("1", "true", "yes"):
        return True
    if text.lower() in ("0", "false", "no"):
        return False
    raise argparse.ArgumentTypeError(f"{text!r}: true or false")


def parse_args() -> Args:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    for f in dataclasses.fields(Args):
        parser.add_argument("--" + f.name.replace("_", "-"), type=boolean if f.type is bool else f.type,
                            default=f.default)
    args = Args(**vars(parser.parse_args()))
    for name in ("num_seeds", "total_timesteps", "num_envs", "num_steps", "num_minibatches", "update_epochs"):
        if getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} {getattr(args, name)}: a positive number")
    batch = args.num_envs * args.num_steps
    if batch % args.num_minibatches:
        divisors = [d for d in range(1, min(batch, 64) + 1) if batch % d == 0]
        parser.error(f"--num-minibatches {args.num_minibatches} does not divide the batch (--num-envs * --num-steps "
                     f"= {batch}) into equal minibatches: choose one of {', '.join(map(str, divisors))}, or change "
                     "--num-envs or --num-steps")
    if args.total_timesteps < batch:
        parser.error(f"--total-timesteps {args.total_timesteps} is less than one iteration (--num-envs * --num-steps "
                     f"= {args.num_envs * args.num_steps}): it would train nothing")
    return args


# ---- the network (spec 1.2, 1.3): Nature CNN torso, actor and critic heads ----

def init_network(torso, actor, critic, height: int, width: int):
    """The parameters from the torso's, the actor's and the critic's keys."""
    k1, k2, k3, k4 = jax.random.split(torso, 4)
    orth = jax.nn.initializers.orthogonal  # a (kh, kw, in, out) kernel as a (kh*kw*in) x out matrix, as Flax
    gain = np.sqrt(2)

    def layer(key, shape, scale):
        return {"w": orth(scale)(key, shape, jnp.float32), "b": jnp.zeros(shape[-1], jnp.float32)}

    h, w = (height - 8) // 4 + 1, (width - 8) // 4 + 1  # the three VALID convolutions' output size
    h, w = (h - 4) // 2 + 1 - 2, (w - 4) // 2 + 1 - 2
    return {"conv1": layer(k1, (8, 8, 3, 32), gain), "conv2": layer(k2, (4, 4, 32, 64), gain),
            "conv3": layer(k3, (3, 3, 64, 64), gain), "dense": layer(k4, (h * w * 64, 512), gain),
            "actor": layer(actor, (512, 8), 0.01), "critic": layer(critic, (512, 1), 1.0)}


def network(params, obs):
    """uint8 [B, H, W, 3] -> logits [B, 8], value [B]."""
    x = obs.astype(jnp.float32) / 255.0  # spec 1.1
    for name, stride in (("conv1", 4), ("conv2", 2), ("conv3", 1)):
        x = jax.lax.conv_general_dilated(x, params[name]["w"], (stride, stride), "VALID",
                                         dimension_numbers=("NHWC", "HWIO", "NHWC"))
        x = jax.nn.relu(x + params[name]["b"])
    x = x.reshape(x.shape[0], -1)  # (row, column, channel) order, as the original
    x = jax.nn.relu(x @ params["dense"]["w"] + params["dense"]["b"])
    logits = x @ params["actor"]["w"] + params["actor"]["b"]
    value = (x @ params["critic"]["w"] + params["critic"]["b"])[:, 0]
    return logits, value


# ---- the optimiser (spec 2.1): global-norm clipping, then Adam(0.9, 0.999, eps) ----

def adam_init(params):
    zeros = jax.tree.map(jnp.zeros_like, params)
    return {"m": zeros, "v": zeros, "count": jnp.int32(0)}


def adam_step(params, grads, opt, args: Args):
    norm = jnp.sqrt(sum(jnp.sum(g * g) for g in jax.tree.leaves(grads)))
    grads = jax.tree.map(lambda g: jnp.where(norm < args.max_grad_norm, g, g / norm * args.max_grad_norm), grads)
    b1, b2, count = 0.9, 0.999, opt["count"] + 1
    m = jax.tree.map(lambda m, g: b1 * m + (1 - b1) * g, opt["m"], grads)
    v = jax.tree.map(lambda v, g: b2 * v + (1 - b2) * g * g, opt["v"], grads)
    step = lambda p, m, v: p - args.learning_rate * (m / (1 - b1**count)) / (jnp.sqrt(v / (1 - b2**count)) + args.adam_eps)
    return jax.tree.map(step, params, m, v), {"m": m, "v": v, "count": count}


# ---- PPO ----

def gae(values, rewards, dones, last_value, last_done, gamma: float, lam: float):
    """Advantages and returns [T, N] (spec 2.5.3). dones[t]: o_t starts an episode; last_value and last_done
    are those of the observation after the last step. Truncation counts as termination: no bootstrap across it."""
    def back(carry, x):
        advantage, next_value, next_done = carry
        value, reward, done = x
        nonterm = 1.0 - next_done
        delta = reward + gamma * next_value * nonterm - value
        advantage = delta + gamma * lam * nonterm * advantage
        return (advantage, value, done.astype(jnp.float32)), advantage
    init = (jnp.zeros_like(last_value), last_value, last_done.astype(jnp.float32))
    _, advantages = jax.lax.scan(back, init, (values, rewards, dones), reverse=True)
    return advantages, advantages + values


def make_train(args: Args, env):
    """init(seed) -> runner and iteration(runner) -> (runner, metrics), for one agent: vmap both."""
    n, t_steps = args.num_envs, args.num_steps
    batch = n * t_steps
    minibatch = batch // args.num_minibatches
    height, width, _ = env.single_observation_space.shape

    def init(seed):
        # spec 2.4: the seed's key split into the carry key and the torso's, actor's and critic's keys.
        key, torso, actor, critic = jax.random.split(jax.random.PRNGKey(seed), 4)
        params = init_network(torso, actor, critic, height, width)
        env_state, obs, _ = env.reset(seed.astype(jnp.uint32))
        return {"params": params, "opt": adam_init(params), "env": env_state, "obs": obs,
                "done": jnp.zeros(n, bool), "key": key}

    def rollout_step(carry, _):  # spec 2.5.1
        params, env_state, obs, done, key = carry
        key, sample_key = jax.random.split(key)
        logits, value = network(params, obs)
        action = jax.random.categorical(sample_key, logits)  # Gumbel-max sampling (spec 1.4)
        logp = jnp.take_along_axis(jax.nn.log_softmax(logits), action[:, None], 1)[:, 0]
        env_state, next_obs, reward, terminated, truncated, info = env.step(env_state, action)
        next_done = terminated.astype(bool) | truncated.astype(bool)  # truncation is termination (2.5.1b)
        ended = info["_final"].astype(bool)  # episodes' metrics from their last state (spec 4.1)
        finals = info["final_info"]
        episodes = {"count": ended.sum(), "success_once": jnp.where(ended, finals["success_once"], 0).sum(),
                    "return": jnp.where(ended, finals["return"], 0.0).sum()}
        # dones[t]: o_t starts an episode, i.e. the previous step's flag (2.5.1d)
        return (params, env_state, next_obs, next_done, key), ((obs, action, logp, value, reward, done), episodes)

    def loss_fn(params, mb):  # spec 2.6
        obs, action, logp_old, value_old, advantage, returns = mb
        logits, value = network(params, obs)
        log_probs = jax.nn.log_softmax(logits)
        logp = jnp.take_along_axis(log_probs, action[:, None], 1)[:, 0]
        clipped = jnp.maximum(log_probs, jnp.finfo(jnp.float32).min)  # no 0 * -inf
        entropy = -(jnp.exp(clipped) * clipped).sum(-1)
        ratio = jnp.exp(logp - logp_old)
        if args.norm_adv:
            advantage = (advantage - advantage.mean()) / (advantage.std() + 1e-8)  # population std
        c = args.clip_coef
        pg_loss = jnp.maximum(-advantage * ratio, -advantage * jnp.clip(ratio, 1 - c, 1 + c)).mean()
        if args.clip_vloss:
            v_clipped = value_old + jnp.clip(value - value_old, -c, c)
            v_loss = 0.5 * jnp.maximum((value - returns) ** 2, (v_clipped - returns) ** 2).mean()
        else:
            v_loss = 0.5 * ((value - returns) ** 2).mean()
        loss = pg_loss - args.ent_coef * entropy.mean() + args.vf_coef * v_loss
        stats = {"loss": loss, "policy_loss": pg_loss, "value_loss": v_loss, "entropy": entropy.mean(),
                 "approx_kl": ((ratio - 1) - jnp.log(ratio)).mean(), "clipfrac": (jnp.abs(ratio - 1) > c).mean()}
        return loss, stats

    def iteration(runner):
        carry = (runner["params"], runner["env"], runner["obs"], runner["done"], runner["key"])
        carry, (transitions, episodes) = jax.lax.scan(rollout_step, carry, None, t_steps)
        params, env_state, obs, done, key = carry
        obs_b, actions, logps, values, rewards, dones = transitions
        _, last_value = network(params, obs)
        advantages, returns = gae(values, rewards, dones, last_value, done, args.gamma, args.gae_lambda)
        flat = jax.tree.map(lambda x: x.reshape((batch,) + x.shape[2:]),
                            (obs_b, actions, logps, values, advantages, returns))

        def epoch(carry, _):  # spec 2.5.4: a fresh permutation per epoch, M minibatches in order
            params, opt, key = carry
            key, perm_key = jax.random.split(key)
            order = jax.random.permutation(perm_key, batch).reshape(args.num_minibatches, minibatch)

            def minibatch_step(carry, index):
                params, opt = carry
                mb = jax.tree.map(lambda x: x[index], flat)
                grads, stats = jax.grad(loss_fn, has_aux=True)(params, mb)
                params, opt = adam_step(params, grads, opt, args)
                return (params, opt), stats

            (params, opt), stats = jax.lax.scan(minibatch_step, (params, opt), order)
            return (params, opt, key), stats

        (params, opt, key), stats = jax.lax.scan(epoch, (params, runner["opt"], key), None, args.update_epochs)
        runner = {"params": params, "opt": opt, "env": env_state, "obs": obs, "done": done, "key": key}
        metrics = {**{k: v.sum() for k, v in episodes.items()}, **jax.tree.map(lambda s: s[-1, -1], stats)}
        return runner, metrics

    return init, iteration


def main() -> None:
    args = parse_args()
    try:
        env = kage.jax.make_env(args.config, args.num_envs)
    except (FileNotFoundError, kage.ConfigError) as e:  # a missing config, a config with errors (located lines)
        raise SystemExit(f"jax_ppo.py: --config: {e}") from None
    init, iteration = make_train(args, env)
    seeds = args.seed + jnp.arange(args.num_seeds)
    # Op by op, not jitted: in one jitted program XLA's CPU runtime may run several batched QR factorisations
    # (the orthogonal initialisations) at once, each waiting on its own tasks in the same thread pool, which
    # deadlocks when the pool has as few threads as they are (seen with jaxlib 0.10 on 2 cores). It runs once.
    runner = jax.vmap(init)(seeds)
    # One program for every agent's whole iteration; the runner (environment state included) is donated,
    # so XLA updates it in place.
    train_iteration = jax.jit(jax.vmap(iteration), donate_argnums=0)
    steps_per_iteration = args.num_envs * args.num_steps
    start = time.perf_counter()
    for i in range(1, args.total_timesteps // steps_per_iteration + 1):
        began = time.perf_counter()
        runner, metrics = train_iteration(runner)
        metrics = jax.device_get(metrics)  # the one host read per iteration, for logging
        now = time.perf_counter()
        count = metrics.pop("count")
        ended = {k: [float(s / c) if c else None for s, c in zip(metrics.pop(k), count)]
                 for k in ("success_once", "return")}
        print(json.dumps({"iteration": i, "global_step": i * steps_per_iteration,
                          "sps": round(args.num_seeds * steps_per_iteration / (now - began)),
                          "elapsed_s": round(now - start, 2), "episodes": [int(c) for c in count], **ended,
                          **{k: [float(x) for x in v] for k, v in metrics.items()}}), flush=True)


if __name__ == "__main__":
    main()
