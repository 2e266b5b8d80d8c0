"""kage.jax on the GPU (issue 23, item 4), one check per subcommand, each printing one summary line:

  equal CONFIG...   kage.jax's jitted lax.scan against make_vec(device="cuda"): the same bytes over --steps
                    steps (obs, reward, flags, every info field; final obs and info where _final)
  speed CONFIG      steps/s of a random-action lax.scan (observations rendered) at --envs environments
  trace CONFIG      the same scan under jax.profiler: per step, each GPU kernel and memory operation, so a
                    host copy or synchronisation inside the scan shows; the trace is saved under --out
  train LOG...      a summary of examples/jax_ppo.py's JSON lines: steady steps/s, train success_once per seed

Run from the repository root with the package built (lab/tools/jax_device.sh does both).
"""
import argparse
import glob
import json
import os
import statistics
import time
from collections import Counter

import numpy as np


def _jax():
    import jax
    import jax.numpy as jnp

    import kage.jax
    assert jax.default_backend() == "gpu", f"JAX runs on {jax.default_backend()}, not the GPU"
    return jax, jnp, kage.jax


def policy(seed: int, num_envs: int, steps: int) -> np.ndarray:
    """[steps, num_envs] int32 actions, mostly right and right+jump (as tests/python/support.py's)."""
    rng = np.random.default_rng(seed)
    return rng.choice(np.array([2, 6, 2, 6, 0, 1, 4, 7], dtype=np.int32), size=(steps, num_envs))


def equal(config: str, envs: int, steps: int, seed: int) -> str:
    jax, jnp, kjax = _jax()
    import kage
    names = [name for name, _, _ in kage.INFO_FIELDS]
    env = kjax.make_env(config, envs)
    actions = policy(seed, envs, steps)

    def run(seed, actions):
        state, obs, info = env.reset(seed)

        def body(state, a):
            state, obs, reward, terminated, truncated, info = env.step(state, a)
            return state, {"obs": obs, "reward": reward, "terminated": terminated, "truncated": truncated,
                           "_final": info["_final"], "final_obs": info["final_obs"], **{k: info[k] for k in names},
                           **{"final_info/" + k: info["final_info"][k] for k in names}}
        return (obs, {k: info[k] for k in names}), jax.lax.scan(body, state, actions)[1]

    (obs0, info0), got = jax.device_get(jax.jit(run)(jnp.uint32(seed), jnp.asarray(actions)))
    vec = kage.make_vec(config, envs, device="cuda")
    obs, info = vec.reset(seed=seed)
    problems = [k for k, a, b in [("reset obs", obs0, obs.numpy())] + [(f"reset {k}", info0[k], info[k].numpy())
                                                                        for k in names] if not np.array_equal(a, b)]
    finals = 0
    for t in range(steps):
        obs, reward, terminated, truncated, info = vec.step(actions[t])
        want = {"obs": obs, "reward": reward, "terminated": terminated, "truncated": truncated,
                "_final": info["_final"], **{k: info[k] for k in names}}
        problems += [f"step {t} {k}" for k, v in want.items() if not np.array_equal(got[k][t], v.numpy())]
        mask = info["_final"].numpy().astype(bool)
        finals += int(mask.sum())
        rows = {"final_obs": info["final_obs"], **{"final_info/" + k: info["final_info"][k] for k in names}}
        problems += [f"step {t} {k}" for k, v in rows.items() if not np.array_equal(got[k][t][mask], v.numpy()[mask])]
        if len(problems) > 5:
            break
    vec.close()
    verdict = "all bytes equal" if not problems else "DIFFER: " + ", ".join(problems[:6])
    return f"equal {config}: {steps} steps x {envs} envs, {finals} finished episodes: {verdict}"


def _random_scan(env, steps: int):
    jax, jnp, _ = _jax()

    def run(state, key):
        def body(carry, _):
            state, key = carry
            key, k = jax.random.split(key)
            state = env.step(state, jax.random.randint(k, (env.num_envs,), 0, 8, dtype=jnp.int32))[0]
            return (state, key), None
        return jax.lax.scan(body, (state, key), None, steps)[0]
    return jax.jit(run, donate_argnums=0)


def speed(config: str, envs: int, steps: int, repeats: int) -> str:
    jax, _, kjax = _jax()
    env = kjax.make_env(config, envs)
    run = _random_scan(env, steps)
    carry = (env.reset(0)[0], jax.random.PRNGKey(0))
    carry = jax.block_until_ready(run(*carry))  # compile and warm up
    began = time.perf_counter()
    for _ in range(repeats):
        carry = run(*carry)
    jax.block_until_ready(carry)
    rate = envs * steps * repeats / (time.perf_counter() - began)
    return f"speed {config}: {envs} envs, random-action lax.scan of {steps} steps: {rate / 1e6:.3f} M steps/s"


def trace(config: str, envs: int, steps: int, out: str) -> str:
    jax, _, kjax = _jax()
    env = kjax.make_env(config, envs)
    run = _random_scan(env, steps)
    carry = jax.block_until_ready(run(env.reset(0)[0], jax.random.PRNGKey(0)))
    folder = os.path.join(out, "jax_trace")
    with jax.profiler.trace(folder):
        carry = jax.block_until_ready(run(*carry))
    data = jax.profiler.ProfileData.from_file(glob.glob(folder + "/**/*.xplane.pb", recursive=True)[0])
    device, host = Counter(), Counter()
    for plane in data.planes:
        for line in plane.lines:
            for event in line.events:
                if plane.name.startswith("/device:GPU"):
                    device[event.name] += 1
                elif "ynchronize" in event.name or "emcpy" in event.name:
                    host[event.name] += 1
    per_step = ", ".join(f"{name} {count / steps:g}" for name, count in device.most_common(12))
    return (f"trace {config}: {steps} steps; GPU events per step: {per_step}; host copy/sync calls in the whole run: "
            f"{dict(host) or 'none'} (saved in {folder})")


def train(logs) -> str:
    lines = []
    for path in logs:
        records = [json.loads(line) for line in open(path) if line.startswith("{")]
        seeds = len(records[0]["loss"])
        steady = statistics.median(r["sps"] for r in records[5:] or records)
        ended = [r for r in records if r["episodes"][0]]  # every seed's episodes end in the same iterations
        last = ended[-1]["success_once"] if ended else [None] * seeds
        text = ", ".join("-" if v is None else f"{v:.2f}" for v in last)
        at = f" (iteration {ended[-1]['iteration']} of {records[-1]['iteration']})" if ended else ""
        # The best value each seed reached, and where: a seed may learn, then collapse to never jumping.
        best = [max(ended, key=lambda r: r["success_once"][s]) for s in range(seeds)] if ended else []
        peaks = ", ".join(f"{r['success_once'][s]:.2f} (it. {r['iteration']})" for s, r in enumerate(best))
        lines.append(f"train {path}: {seeds} seed(s), {records[-1]['global_step']} steps each, steady "
                     f"{steady / 1e3:.1f} k steps/s over all seeds; train success_once per seed at the last "
                     f"episode end{at}: {text}; best per seed: {peaks or '-'}")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("what", choices=["equal", "speed", "trace", "train"])
    parser.add_argument("paths", nargs="+", help="configs (train: JSON-line logs)")
    parser.add_argument("--envs", type=int, default=16)
    parser.add_argument("--steps", type=int, default=600)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--seed", type=int, default=7)
    parser.add_argument("--out", default=os.environ.get("OUT", "."))
    a = parser.parse_args()
    for path in a.paths if a.what != "train" else [a.paths]:
        if a.what == "equal":
            print(equal(path, a.envs, a.steps, a.seed), flush=True)
        elif a.what == "speed":
            print(speed(path, a.envs, a.steps, a.repeats), flush=True)
        elif a.what == "trace":
            print(trace(path, a.envs, a.steps, a.out), flush=True)
        else:
            print(train(path), flush=True)


if __name__ == "__main__":
    main()
