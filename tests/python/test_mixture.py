"""kage.make_vec over a list of configs (kage.mixture): the split, the mixture against its configs stepped alone
byte for byte per slice, info["config"], the saved state, and every refusal before anything is made."""
import math
import warnings

import numpy as np
import pytest

import kage
from kage import front_end, mixture
from support import CONFIGS, NEAR_GOAL, SIMPLEST, policy

NEAR_GOAL_RED = str(CONFIGS / "near_goal_red.yaml")        # near_goal with red platforms (layout colour)
NEAR_GOAL_NOISY = str(CONFIGS / "near_goal_noisy.yaml")    # noise background, pixel noise, distractors
LONG_EPISODE = str(CONFIGS / "long_episode.yaml")          # simplest with episode_length 1000 (latent)
SMALL_FRAME = str(CONFIGS / "small_frame.yaml")            # simplest with 64 x 64 observations
MIX = [NEAR_GOAL, NEAR_GOAL_RED, NEAR_GOAL_NOISY]
FINAL = ("final_obs", "final_info", "_final", "_final_obs", "_final_info")


@pytest.mark.parametrize("num_envs, weights, counts", [
    (10, None, (4, 3, 3)),                # 3.33 each: floors 3, 3, 3; the one left to the first (a tie)
    (7, [2, 1, 1], (3, 2, 2)),            # 3.5, 1.75, 1.75: floors 3, 1, 1; the two left to the larger remainders
    (5, [1, 0, 1], (3, 0, 2)),            # 2.5, 0, 2.5: a tie goes to the earlier config
    (1, [1, 1, 1], (1, 0, 0)),
    (9, [0.5, 0.25, 0.25], (5, 2, 2)),    # 4.5, 2.25, 2.25: floors 4, 2, 2; the one left to the remainder 0.5
    (4, [np.float32(3), 1, np.int64(0)], (3, 1, 0)),
])
def test_the_split_floors_the_shares_then_gives_the_rest_by_largest_remainder(num_envs, weights, counts):
    assert mixture.split(num_envs, mixture.weights_of(weights, 3)) == counts
    assert mixture.config_index(counts).tolist() == sum(([k] * n for k, n in enumerate(counts)), [])


def test_the_split_is_exact():
    # 0.1, 0.2 and 0.7 are not exactly tenths (the three doubles sum to 1 - 2**-55): the exact shares of 10 are
    # just above 1, just above 2 and just under 7, so the one environment left goes to the third.
    assert mixture.split(10, mixture.weights_of([0.1, 0.2, 0.7], 3)) == (1, 2, 7)
    assert sum(mixture.split(1000, mixture.weights_of([1 / 3, 1 / 3, 1 / 3], 3))) == 1000


def run_mixture(configs, num_envs, weights, seed, steps, threads=None):
    """Every step's outputs of make_vec's mixture, copied."""
    out = []
    with kage.make_vec(configs, num_envs, seed=seed, weights=weights, threads=threads) as env:
        out.append(copies(*env.reset(seed=seed)))
        for actions in policy(seed, num_envs, steps):
            out.append(copies(*env.step(actions)))
        counts = env.counts
    return out, counts


def copies(*outputs):
    """A step's outputs as numpy copies: obs, then reward, terminated, truncated (absent after a reset), info."""
    *arrays, info = outputs
    flat = {f"out{i}": np.array(a, copy=True) for i, a in enumerate(arrays)}
    flat.update({k: np.array(v, copy=True) for k, v in info.items() if k not in ("final_info",)})
    flat.update({f"final_info/{k}": np.array(v, copy=True) for k, v in info["final_info"].items()})
    return flat


def test_a_mixture_equals_its_configs_stepped_alone_byte_for_byte(tmp_path):
    seed, n, steps = 5, 7, 300  # 40-step episodes: seven automatic resets of every environment
    mixed, counts = run_mixture(MIX, n, [2, 1, 1], seed, steps, threads=3)
    assert counts == (3, 2, 2)
    seeds = kage.env_seeds(seed, n)
    actions = policy(seed, n, steps)
    start = 0
    for k, (config, count) in enumerate(zip(MIX, counts)):
        part = slice(start, start + count)
        with kage.make_vec(config, count, threads=1) as alone:
            expected = [copies(*alone.reset(seed=seeds[part].tolist()))]
            for a in actions:
                expected.append(copies(*alone.step(a[part])))
        for t, (m, e) in enumerate(zip(mixed, expected)):
            assert m.keys() == e.keys()
            for name in e:
                if name in ("config", "final_info/config"):
                    assert e[name].tolist() == [0] * count  # alone, each is config 0
                    assert m[name][part].tolist() == [k] * count, (t, name)
                    continue
                assert m[name][part].tobytes() == e[name].tobytes(), (config, t, name)
        start += count
    # Not vacuous: episodes ended and restarted, pixels and rewards vary, and the configs look different.
    assert sum(int(m["_final"].sum()) for m in mixed) == 7 * n
    assert np.unique(mixed[-1]["out0"]).size > 10 and np.ptp(np.stack([m["out1"] for m in mixed[1:]])) > 0
    frame = mixed[1]["out0"]
    assert not np.array_equal(frame[0], frame[3]) and not np.array_equal(frame[3], frame[5])


def test_results_do_not_depend_on_the_thread_count():
    one, _ = run_mixture(MIX, 6, None, 2, 60, threads=1)
    four, _ = run_mixture(MIX, 6, None, 2, 60, threads=4)
    for a, b in zip(one, four):
        assert all(a[k].tobytes() == b[k].tobytes() for k in a)


def test_a_mixture_is_one_batch_with_one_set_of_outputs():
    with kage.make_vec(MIX, 5, weights=[1, 3, 1]) as env:
        obs, info = env.reset(seed=0)
        assert env.counts == (1, 3, 1) and env.num_envs == 5 and obs.shape == (5, 128, 128, 3)
        assert info["config"].dtype == np.int32 and info["config"].tolist() == [0, 1, 1, 1, 2]
        assert info["final_info"]["config"].tolist() == [0, 1, 1, 1, 2]
        # One observation buffer, the runtime's (no copy): every part renders into its slice.
        assert obs.ctypes.data == env._handle.data_ptr("obs") and obs.flags.c_contiguous
        assert info["config"].ctypes.data == env._handle.data_ptr("info/config")
        hashes = [front_end.resolve(c)["sha256"] for c in MIX]
        assert env.spec_hash == front_end.mixture_hash(hashes, (1, 3, 1)) != front_end.mixture_hash(hashes, (2, 2, 1))
        assert [s["sha256"] for s in env.resolved_specs] == hashes
        with pytest.raises(ValueError, match="mixture of 3 configs.*resolved_specs"):
            env.resolved_spec
        assert env.configs == tuple(MIX) and "JaxMixture" not in repr(env)


def test_a_saved_mixture_continues_exactly():
    with kage.make_vec(MIX, 4) as a, kage.make_vec(MIX, 4) as b:
        a.reset(seed=9)
        for actions in policy(1, 4, 30):
            a.step(actions)
        b.load_state(a.save_state())
        for actions in policy(2, 4, 30):
            oa, ra, *_ = a.step(actions)
            ob, rb, *_ = b.step(actions)
            assert oa.tobytes() == ob.tobytes() and ra.tobytes() == rb.tobytes()
        with kage.make_vec(MIX, 4, weights=[1, 2, 1]) as other:  # counts (1, 2, 1), not (2, 1, 1)
            with pytest.raises(ValueError, match="spec hash"):
                other.load_state(a.save_state())


def refused(error) -> str:
    """The refusal's text: one line."""
    text = str(error.value)
    assert "\n" not in text.strip(), text
    return text


@pytest.fixture
def nothing_opened(monkeypatch):
    """Counts the batches opened: a refusal opens none."""
    opened = []
    real = kage.vector.native()

    class Spy:
        def __getattr__(self, name):
            return getattr(real, name)

        def open(self, *args):
            opened.append(args)
            return real.open(*args)

        def open_mixture(self, *args):
            opened.append(args)
            return real.open_mixture(*args)

    monkeypatch.setattr(kage.vector, "native", lambda: Spy())
    yield opened
    assert opened == []


def test_a_latent_difference_is_refused_in_one_located_line(nothing_opened):
    with pytest.raises(kage.ConfigError) as e:
        kage.make_vec([SIMPLEST, LONG_EPISODE], 4)
    (error,) = e.value.errors
    assert (error.file, error.line, error.col) == (LONG_EPISODE, 4, 1)  # where long_episode.yaml sets it
    assert "latent key 'episode_length' is 500 in" in error.message and "but 1000 in" in error.message
    assert SIMPLEST in error.message and LONG_EPISODE in error.message
    assert error.message.endswith("[certify-mixture-latent]")


def test_a_different_observation_shape_is_refused_in_one_located_line(nothing_opened):
    with pytest.raises(kage.ConfigError) as e:
        kage.make_vec([SIMPLEST, SMALL_FRAME], 4)
    (error,) = e.value.errors
    assert (error.file, error.line) == (SMALL_FRAME, 3)  # H: 64
    assert "observations are 128x128 (height x width) in" in error.message and "but 64x64 in" in error.message
    assert error.message.endswith("[certify-mixture-shape]")


@pytest.mark.parametrize("weights, text", [
    ([1, -1, 1], r"^weights\[1\]=-1: a finite number >= 0$"),
    ([1, math.nan, 1], r"^weights\[1\]=nan: a finite number >= 0$"),
    ([1, 1, math.inf], r"^weights\[2\]=inf: a finite number >= 0$"),
    ([0, 0.0, 0], r"^weights: all zero; give at least one config a positive weight$"),
    ([1, 1], r"^weights: 2 given for 3 configs: one weight per config$"),
    ([1, True, 1], r"^weights\[1\]=True: a number \(int or float\), one per config$"),
    ("111", r"^weights='111': a list of 3 non-negative numbers, one per config$"),
    ([1, 10 ** 400, 1], r"^weights\[1\]=1000000000000000000000000000000000000\.\.\.: a finite number >= 0$"),
])
def test_bad_weights_are_refused_in_one_line(nothing_opened, weights, text):
    with pytest.raises(ValueError, match=text) as e:
        kage.make_vec(MIX, 4, weights=weights)
    refused(e)


def test_other_refusals_are_one_line_each(nothing_opened, tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        kage.make_vec([NEAR_GOAL, str(tmp_path / "missing.yaml")], 2)
    assert "missing.yaml" in refused(e)
    with pytest.raises(ValueError, match="an empty list") as e:
        kage.make_vec([], 2)
    refused(e)
    with pytest.raises(ValueError, match="weights= splits a mixture") as e:
        kage.make_vec(NEAR_GOAL, 2, weights=[1])
    refused(e)
    with pytest.raises(kage.ConfigError, match=r"\[certify-mixture-latent\]"):  # the certificate first on the GPU too
        kage.make_vec([SIMPLEST, LONG_EPISODE], 4, device="cuda")
    with pytest.raises(TypeError, match=r"configs\[1\]") as e:
        kage.make_vec([NEAR_GOAL, 3], 2)
    refused(e)
    (tmp_path / "compiled").mkdir()
    (tmp_path / "compiled" / "manifest.json").write_text("{}")  # what kagec compile writes there
    with pytest.raises(ValueError, match="is a kagec compile directory") as e:
        kage.make_vec([NEAR_GOAL, str(tmp_path / "compiled")], 2)
    refused(e)
    (tmp_path / "folder").mkdir()
    with pytest.raises(ValueError, match="folder is a directory, not a YAML config: name the config file in it") as e:
        kage.make_vec([NEAR_GOAL, str(tmp_path / "folder")], 2)
    refused(e)


def test_the_certificate_names_the_axes_that_differ():
    cert = front_end.certify_mixture(MIX)
    assert cert["certified"] and [c["name"] for c in cert["configs"]] == MIX
    assert cert["axes"] == ["background", "distractors", "filters", "layout"]
    with pytest.raises(kage.ConfigError, match="certify-mixture-latent"):
        front_end.certify_mixture([NEAR_GOAL, NEAR_GOAL_RED, LONG_EPISODE])


def test_a_config_the_split_leaves_without_environments_is_warned_of():
    # 2 environments over three equal weights: shares 2/3 each, floors 0, the two left over to configs 0 and 1.
    with pytest.warns(UserWarning, match=r"kage.make_vec: 2 environments split as \[1, 1, 0\] leave configs\[2\] "
                                         r"'.*near_goal_noisy.yaml' \(weight 1\) none, so it runs nowhere"):
        with kage.make_vec(MIX, 2) as env:
            assert env.counts == (1, 1, 0)
    # A weight of 0 asks for no environment: no warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with kage.make_vec(MIX, 2, weights=[1, 1, 0]) as env:
            assert env.counts == (1, 1, 0)
