"""GPU tests of the Python package: run on a machine with a CUDA GPU (lab/tools/python_device.sh), never
in CI. A missing GPU or torch without CUDA stops the run with an error, not a skip. `deterministic`: cuDNN's
deterministic algorithms for a test, so that bit equality can be its check."""
import pathlib
import sys

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "python"))


def pytest_configure(config):
    import torch

    if not torch.cuda.is_available():
        raise pytest.UsageError("tests/gpu needs a CUDA GPU and torch with CUDA")


@pytest.fixture
def deterministic(monkeypatch):
    import torch

    monkeypatch.setattr(torch.backends.cudnn, "deterministic", True)
    before = torch.are_deterministic_algorithms_enabled(), torch.is_deterministic_algorithms_warn_only_enabled()
    torch.use_deterministic_algorithms(True, warn_only=True)  # a warning names any op without such an algorithm
    yield
    torch.use_deterministic_algorithms(before[0], warn_only=before[1])
