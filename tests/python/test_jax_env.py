"""kage.jax on the CPU against kage.make_vec, the reference for every byte: a jitted lax.scan of 600 steps
(past the automatic reset at 500), vmap, several configs in one process, and the errors of make_env, of
trace time, of out-of-range actions and of a handler inside jit."""
import os
import subprocess
import sys

import numpy as np
import pytest

jax = pytest.importorskip("jax", reason="kage.jax needs JAX (pip install jax); CI installs it")
import jax.numpy as jnp  # noqa: E402

import kage  # noqa: E402
import kage.jax  # noqa: E402
from support import CONFIGS, NOISY_SKELETON, SIMPLEST, policy  # noqa: E402

NAMES = [name for name, _, _ in kage.INFO_FIELDS]


def vec_rollout(config, num_envs, seed, actions):
    """make_vec's reset (obs, info) and per step (obs, reward, terminated, truncated, info), copied."""
    env = kage.make_vec(config, num_envs, threads=1)
    obs, info = env.reset(seed=seed)
    first = (obs.copy(), {k: info[k].copy() for k in NAMES})
    steps = []
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        steps.append({"obs": obs.copy(), "reward": reward.copy(), "terminated": terminated.copy(),
                      "truncated": truncated.copy(), "_final": info["_final"].copy(),
                      "final_obs": info["final_obs"].copy(),
                      **{k: info[k].copy() for k in NAMES},
                      **{"final_info/" + k: info["final_info"][k].copy() for k in NAMES}})
    env.close()
    return first, {k: np.stack([s[k] for s in steps]) for k in steps[0]}


def jax_rollout(env):
    """A function of (seed, actions [T, N]) -> reset (obs, info) and the stacked step outputs, as
    vec_rollout names them: one reset and one lax.scan."""
    def run(seed, actions):
        state, obs, info = env.reset(seed)

        def body(state, a):
            state, obs, reward, terminated, truncated, info = env.step(state, a)
            out = {"obs": obs, "reward": reward, "terminated": terminated, "truncated": truncated,
                   "_final": info["_final"], "final_obs": info["final_obs"],
                   **{k: info[k] for k in NAMES}, **{"final_info/" + k: info["final_info"][k] for k in NAMES}}
            return state, out

        _, steps = jax.lax.scan(body, state, actions)
        return (obs, {k: info[k] for k in NAMES}), steps
    return run


def assert_same(got, want, what):
    """Equal bytes, dtypes and shapes; on failure the first step and environment that differ."""
    got = np.asarray(got)
    assert got.dtype == want.dtype and got.shape == want.shape, f"{what}: {got.dtype}{got.shape} vs {want.dtype}{want.shape}"
    if not np.array_equal(got, want):
        where = np.argwhere(got != want)[0]
        pytest.fail(f"{what}: first difference at index {tuple(where)}: {got[tuple(where)]} vs {want[tuple(where)]}")


def test_scan_of_600_steps_equals_make_vec():
    n, steps, seed = 2, 600, 11
    actions = policy(seed, n, steps).astype(np.int32)
    (vec_obs0, vec_info0), vec = vec_rollout(SIMPLEST, n, seed, actions)
    env = kage.jax.make_env(SIMPLEST, n)
    (obs0, info0), got = jax.jit(jax_rollout(env))(jnp.uint32(seed), jnp.asarray(actions))
    assert_same(obs0, vec_obs0, "reset obs")
    for k in NAMES:
        assert_same(info0[k], vec_info0[k], f"reset info[{k!r}]")
    assert set(got) == set(vec)
    for k in vec:
        assert_same(got[k], vec[k], k)
    # The data is not trivial: the agents move and earn rewards, and every episode ends at step 500 (index
    # 499) and no other, where the final observation is a drawn frame.
    final = np.asarray(got["_final"]).astype(bool)
    assert final[499].all() and final.sum() == n
    assert np.abs(np.asarray(got["reward"])).sum() > 0 and np.ptp(np.asarray(got["x"])) > 10
    final_obs = np.asarray(got["final_obs"])
    assert final_obs[499].std() > 0
    # Rows whose _final is false hold the environment's previous final observation: zeros before step 500.
    assert not final_obs[:499].any() and (final_obs[500:] == final_obs[499]).all()


def test_vmap_over_batches_equals_separate_runs():
    n, steps = 2, 50  # NOISY_SKELETON's episodes last 40 steps: the scan crosses an automatic reset
    env = kage.jax.make_env(NOISY_SKELETON, n)
    seeds = jnp.asarray([5, 9], jnp.uint32)
    actions = np.stack([policy(s, n, steps) for s in (5, 9)]).astype(np.int32)
    run = jax_rollout(env)
    alone = [jax.jit(run)(seeds[b], jnp.asarray(actions[b])) for b in range(2)]
    together = jax.jit(jax.vmap(run))(seeds, jnp.asarray(actions))
    shared = jax.jit(jax.vmap(run, in_axes=(0, None)))(seeds, jnp.asarray(actions[0]))
    shared_alone = jax.jit(run)(seeds[1], jnp.asarray(actions[0]))
    for b in range(2):
        jax.tree.map(lambda t, a: assert_same(t[b], np.asarray(a), "vmap"), together, alone[b])
    jax.tree.map(lambda t, a: assert_same(t[0], np.asarray(a), "in_axes=(0, None)"), shared, alone[0])
    jax.tree.map(lambda t, a: assert_same(t[1], np.asarray(a), "in_axes=(0, None)"), shared, shared_alone)
    # And a batch alone is make_vec's, autoreset and noise included.
    _, vec = vec_rollout(NOISY_SKELETON, n, 5, actions[0])
    for k in vec:
        assert_same(alone[0][1][k], vec[k], k)
    assert np.asarray(alone[0][1]["_final"]).sum() == n


def test_rejit_second_config_and_foreign_state():
    a = jnp.asarray([2, 6], jnp.int32)
    simple = kage.jax.make_env(SIMPLEST, 2)
    noisy = kage.jax.make_env(NOISY_SKELETON, 2)
    s1, _, _ = simple.reset(1)
    s2, _, _ = noisy.reset(1)
    first = jax.jit(simple.step)(s1, a)
    again = jax.jit(simple.step)(s1, a)  # a second jit of the same function
    jax.tree.map(lambda x, y: assert_same(x, np.asarray(y), "re-jit"), first, again)
    # Both configs in one process, each stepping as its own make_vec.
    for env, state, config in ((simple, s1, SIMPLEST), (noisy, s2, NOISY_SKELETON)):
        _, obs, *_ = jax.jit(env.step)(state, a)
        _, vec = vec_rollout(config, 2, 1, np.asarray(a)[None])
        assert_same(obs, vec["obs"][0], config)
    # The same config made twice shares its registration.
    twice = kage.jax.make_env(SIMPLEST, 2)
    assert_same(jax.jit(twice.step)(s1, a)[1], np.asarray(first[1]), "same config twice")
    with pytest.raises(ValueError, match="belongs to the config with spec hash"):
        noisy.step(s1, a)


def test_donated_state_is_updated_in_place():
    env = kage.jax.make_env(SIMPLEST, 2)
    a = jnp.asarray([2, 6], jnp.int32)
    state, _, _ = env.reset(3)
    kept = jax.jit(env.step)(state, a)
    donated = jax.jit(env.step, donate_argnums=0)(state, a)
    assert state.latent.is_deleted() and state.final_obs.is_deleted()
    jax.tree.map(lambda x, y: assert_same(x, np.asarray(y), "donated"), donated, kept)


def test_trace_time_errors():
    env = kage.jax.make_env(SIMPLEST, 2)
    state = jax.eval_shape(env.reset, jnp.uint32(0))[0]
    good = jax.ShapeDtypeStruct((2,), jnp.int32)
    jax.eval_shape(env.step, state, good)
    with pytest.raises(TypeError, match=r"actions: dtype float32, expected int32"):
        jax.eval_shape(env.step, state, jax.ShapeDtypeStruct((2,), jnp.float32))
    with pytest.raises(ValueError, match=r"actions: shape \(3,\), expected \(2,\)"):
        jax.eval_shape(env.step, state, jax.ShapeDtypeStruct((3,), jnp.int32))
    wrong_dtype = state.__class__(**{**vars(state), "latent": jax.ShapeDtypeStruct(state.latent.shape, jnp.int32)})
    with pytest.raises(TypeError, match=r"state.latent: dtype int32, expected uint8"):
        jax.eval_shape(env.step, wrong_dtype, good)
    three = kage.jax.make_env(SIMPLEST, 3)
    with pytest.raises(ValueError, match=r"state.seeds: shape \(2, 2\), expected \(3, 2\)"):
        jax.eval_shape(three.step, state, jax.ShapeDtypeStruct((3,), jnp.int32))
    with pytest.raises(TypeError, match="seed: a non-negative int or a uint32 scalar, got int32"):
        jax.eval_shape(env.reset, jax.ShapeDtypeStruct((), jnp.int32))
    with pytest.raises(ValueError, match="seed=-1"):
        env.reset(-1)


def test_out_of_range_actions_are_recorded_and_checked():
    env = kage.jax.make_env(SIMPLEST, 2)
    state, _, _ = env.reset(4)
    sent = np.array([[9, 2], [1, -1], [1, 2]], np.int32)
    step = jax.jit(env.step)
    clean = state
    for a in sent:
        state, obs, *_ = step(state, jnp.asarray(a))
    env.check(clean)  # nothing recorded: returns
    with pytest.raises(ValueError, match=r"step 1 held 9 for environment 0 \(2 environments had one\): an action is"):
        env.check(state)
    # The steps ran with the low 3 bits (spec 3.2): 9 -> 1, -1 -> 7.
    _, vec = vec_rollout(SIMPLEST, 2, 4, sent & 7)
    assert_same(obs, vec["obs"][-1], "masked actions")


def test_handler_error_inside_jit():
    """A handler's error reaches the caller as JAX's runtime error, with the handler's text."""
    kage.jax.make_env(SIMPLEST, 1)  # registers the targets
    call = jax.ffi.ffi_call("kage_reset", jax.ShapeDtypeStruct((1, 60), jnp.uint8), vmap_method="broadcast_all")
    with pytest.raises(jax.errors.JaxRuntimeError, match="kage.jax: instantiate: no config with spec hash 0+ in this"):
        jax.jit(lambda s: call(s, spec_hash="0" * 64))(jnp.zeros((1, 2), jnp.uint32))


@pytest.mark.parametrize("seed", [0, 1, 7, 2**31, 2**32 - 1])
def test_seeds_in_graph_are_make_vecs(seed):
    from kage.jax.seeds import env_seed_words
    want = kage.env_seeds(seed, 5)
    words = jax.jit(env_seed_words, static_argnums=1)(jnp.uint32(seed), 5)
    assert_same(np.asarray(words).view("<u8").ravel(), want, f"seeds of {seed}")
    batched = jax.jit(jax.vmap(env_seed_words, in_axes=(0, None)), static_argnums=1)(jnp.asarray([seed, 3], jnp.uint32), 5)
    assert_same(np.asarray(batched[0]).view("<u8").ravel(), want, f"vmapped seeds of {seed}")


def test_seed_beyond_32_bits_resets_as_make_vec():
    env = kage.jax.make_env(SIMPLEST, 2)
    _, obs, info = env.reset(2**40 + 5)
    vec = kage.make_vec(SIMPLEST, 2, threads=1)
    vec_obs, vec_info = vec.reset(seed=2**40 + 5)
    assert_same(obs, vec_obs, "obs")
    assert_same(info["x"], vec_info["x"], "x")


def test_make_env_errors_are_make_vecs():
    bad = str(CONFIGS / "bad_value.yaml")
    with pytest.raises(kage.ConfigError) as vec_error:
        kage.make_vec(bad, 2)
    with pytest.raises(kage.ConfigError) as jax_error:
        kage.jax.make_env(bad, 2)
    assert str(jax_error.value) == str(vec_error.value) and "bad_value.yaml:5:12: error:" in str(jax_error.value)
    with pytest.raises(FileNotFoundError, match="no/such.yaml"):
        kage.jax.make_env("no/such.yaml", 2)
    with pytest.raises(ValueError, match="num_envs=0"):
        kage.jax.make_env(SIMPLEST, 0)


def test_import_without_jax_says_how_to_get_it():
    code = ("import sys\nsys.modules['jax'] = None  # as if JAX were not installed\n"
            "try:\n    import kage.jax\nexcept ImportError as e:\n    print(e)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=dict(os.environ))
    assert "kage.jax needs JAX: `pip install jax`" in done.stdout, done.stdout + done.stderr


# ---- make_vec's limits, and messages that name the argument (issue 37) ----

def refusal_text(call):
    """The text of the ValueError `call` raises, from its "cannot build" on (each caller names itself before)."""
    with pytest.raises(ValueError) as error:
        call()
    text = str(error.value)
    return text[text.index("cannot build"):] if "cannot build" in text else text


def test_make_env_refuses_what_make_vec_refuses():
    """2**40 environments were accepted (and reset derived their seeds in a Python loop, to gigabytes); every
    count that make_vec refuses, by its int32 limit or by memory, make_env refuses in make_vec's words."""
    frame = int(np.prod(kage.make_vec(SIMPLEST, 1, threads=1).single_observation_space.shape))
    memory = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    for n in (2**40, 2**31, 0, -3):
        with pytest.raises(ValueError, match=r"num_envs=-?\d+: a positive integer up to 2147483647") as error:
            kage.make_vec(SIMPLEST, n)
        with pytest.raises(ValueError) as jax_error:
            kage.jax.make_env(SIMPLEST, n)
        assert str(jax_error.value) == str(error.value)
    # Two frames an environment (its observation and its final one) already pass half of the memory.
    for n in (2**31 - 1, memory // frame):
        vec = refusal_text(lambda: kage.make_vec(SIMPLEST, n))
        assert "more than half of this machine's" in vec, vec
        with pytest.raises(ValueError, match=rf"^kage.jax.make_env: num_envs={n}: cannot build") as error:
            kage.jax.make_env(SIMPLEST, n)
        assert vec in str(error.value)
    assert kage.jax.make_env(SIMPLEST, 3).num_envs == 3


def test_seed_words_of_many_environments_are_make_vecs():
    """The output constants of 2 N words come from one numpy pass, not a Python loop of 2 N steps."""
    from kage.jax.seeds import _output_constants, env_seed_words
    _output_constants.cache_clear()
    words = env_seed_words(jnp.uint32(12), 200_000)
    assert_same(np.asarray(words).view("<u8").ravel(), kage.env_seeds(12, 200_000), "seeds of 200,000 environments")


@pytest.mark.parametrize("actions, error, said", [
    ("01", TypeError, r"^actions='01': a str, expected int32 \[2\], one action in 0..7 per environment"),
    ([2**31, 0], ValueError, r"^actions: 2147483648 does not fit int32 \(and actions are 0..7\)"),
    ([2**64, 0], ValueError, rf"^actions: {2**64} does not fit int32"),
    (b"\x01\x02", TypeError, r"^actions=b'\\x01\\x02': a bytes, expected int32"),
    ([None, 1], TypeError, r"^actions: object values \(\[None, 1\]\), expected int32 \[2\]"),
    ([[1, 2]], ValueError, r"^actions: shape \(1, 2\), expected \(2,\)"),
], ids=["string", "beyond-int32", "beyond-int64", "bytes", "none", "nested"])
def test_actions_that_are_not_int32_name_the_argument(actions, error, said):
    env = kage.jax.make_env(SIMPLEST, 2)
    state, _, _ = env.reset(0)
    with pytest.raises(error, match=said):
        env.step(state, actions)
    state, *_ = env.step(state, [1, 6])  # a list of small ints is still taken, as int32
    env.check(state)


def test_check_inside_jit_says_to_call_it_outside():
    env = kage.jax.make_env(SIMPLEST, 2)
    state, _, _ = env.reset(0)
    outside = "reads the state's action record back from the device, so it runs outside jax.jit, vmap and scan"
    with pytest.raises(TypeError, match=outside):
        jax.jit(env.check)(state)
    batched = jax.vmap(env.reset)(jnp.asarray([1, 2], jnp.uint32))[0]
    with pytest.raises(TypeError, match=outside):
        jax.vmap(env.check)(batched)
    with pytest.raises(TypeError, match=outside):
        jax.lax.scan(lambda s, _: (s, env.check(s)), state, None, length=1)
    env.check(batched)  # outside: a batched state is checked whole
