"""kage.resources: shipped configs and suites by name, the data root of a build tree, and where the
extension looks for NVRTC (the nvidia-cuda-nvrtc wheel of scripts/constraints.txt first)."""
import importlib.metadata
import os
import pathlib

import pytest

from kage import _native, resources

REPO = pathlib.Path(__file__).resolve().parents[2]


def test_a_build_tree_package_reads_its_source_tree():
    assert resources.source_root() == REPO
    assert resources.data_root() == REPO
    assert resources.runtime_include_dir() == str(REPO)


def test_shipped_configs_and_suites_by_name():
    assert resources.config_path("throughput/simplest") == str(REPO / "configs/throughput/simplest.yaml")
    assert resources.config_path("kage_bench/bases/shape_black.yaml") == str(
        REPO / "configs/kage_bench/bases/shape_black.yaml")
    assert resources.config_path("configs/throughput/hardest") == str(REPO / "configs/throughput/hardest.yaml")
    assert resources.suite_path("kage_bench") == str(REPO / "suites/kage_bench.yaml")


def test_an_existing_path_is_taken_as_it_is(tmp_path):
    config = tmp_path / "mine.yaml"
    config.write_text("extends: whatever\n")
    assert resources.config_path(str(config)) == str(config)
    assert resources.config_path(str(tmp_path)) == str(tmp_path)  # a kagec compile folder


def test_an_unknown_name_lists_near_ones():
    with pytest.raises(FileNotFoundError) as e:
        resources.config_path("throughput/simplst")
    assert "'throughput/simplst' is neither a path nor a shipped config name" in str(e.value)
    assert "near names: throughput/simplest" in str(e.value)
    with pytest.raises(FileNotFoundError, match="near names: kage_bench"):
        resources.suite_path("kage_bnch")


def test_a_folder_of_shipped_configs_names_what_it_holds(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # where configs/kage_bench is no path: it was called "neither a path nor a name"
    with pytest.raises(FileNotFoundError) as e:
        resources.config_path("configs/kage_bench/bases")
    assert str(e.value) == ("config 'configs/kage_bench/bases' is a folder of shipped configs, not one: name one of "
                            "them (kage_bench/bases/image_shape, kage_bench/bases/image_skeleton, "
                            "kage_bench/bases/shape_black, kage_bench/bases/skeleton_black)")


def test_make_vec_takes_a_shipped_name():
    import kage

    env = kage.make_vec("throughput/simplest", 2)
    env.reset(seed=0)
    assert env.config == str(REPO / "configs/throughput/simplest.yaml")


def test_the_trainer_and_the_evaluator_take_shipped_names(tmp_path):
    from kage.ppo import args as train_args
    from kage.ppo import evaluate

    args = train_args.parse_args(["--train-config-path", "kage_bench/bases/shape_black", "--eval-config-paths",
                                  "kage_bench/background/1-eval", "throughput/simplest", "--device", "cpu"])
    assert args.train_config_path == str(REPO / "configs/kage_bench/bases/shape_black.yaml")
    assert args.eval_config_paths == [str(REPO / "configs/kage_bench/background/1-eval.yaml"),
                                      str(REPO / "configs/throughput/simplest.yaml")]
    with pytest.raises(SystemExit) as e:  # the evaluator's unknown name: near names, no traceback
        evaluate.open_env("kage_bench/background/1-evl", 1, {}, "latest.pt", None)
    assert "'kage_bench/background/1-evl' is neither a path nor a shipped config name" in str(e.value)
    assert "near names: kage_bench/background/1-eval" in str(e.value)


def test_the_nvrtc_wheel_is_searched_first(monkeypatch):
    wheel = importlib.metadata.distribution("nvidia-cuda-nvrtc")  # pinned in scripts/constraints.txt
    lib = [f for f in wheel.files if f.name == "libnvrtc.so.13"]
    assert len(lib) == 1
    wheel_dir = str(pathlib.Path(wheel.locate_file(lib[0])).parent)
    assert resources.nvrtc_dirs() == [wheel_dir]

    native = _native.native()  # its first load named the wheel's folder
    monkeypatch.setenv("CUDA_HOME", "/opt/cuda-home")
    monkeypatch.delenv("CUDA_PATH", raising=False)
    names = ["libnvrtc.so.13", "libnvrtc.so.12", "libnvrtc.so"]
    candidates = native.nvrtc_candidates()
    assert candidates[:9] == [f"{wheel_dir}/{n}" for n in names] + [f"/opt/cuda-home/lib64/{n}" for n in names] + names
    assert candidates[-3:] == [f"/usr/local/cuda/lib64/{n}" for n in names]
    middle = candidates[9:-3]
    if native.gpu_backend_built():  # the folder of the NVRTC library beside the nvrtc.h the build used
        assert [os.path.basename(c) for c in middle] == names
    else:
        assert middle == []
    native.set_nvrtc_dirs(["/a", "/b"])
    try:
        assert native.nvrtc_candidates()[:6] == [f"/a/{n}" for n in names] + [f"/b/{n}" for n in names]
    finally:
        native.set_nvrtc_dirs(resources.nvrtc_dirs())


def test_the_version_is_the_projects():
    import kage

    cmake = (REPO / "CMakeLists.txt").read_text()
    assert f"project(kagec VERSION {kage.__version__} " in cmake
    assert os.path.isfile(REPO / "CHANGELOG.md") and f"## {kage.__version__}" in (REPO / "CHANGELOG.md").read_text()
