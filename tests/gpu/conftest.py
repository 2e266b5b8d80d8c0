"""GPU tests of the Python package: run on a machine with a CUDA GPU (lab/tools/python_device.sh), never
in CI. A missing GPU or torch without CUDA stops the run with an error, not a skip."""
import pathlib
import sys

import pytest

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "python"))


def pytest_configure(config):
    import torch

    if not torch.cuda.is_available():
        raise pytest.UsageError("tests/gpu needs a CUDA GPU and torch with CUDA")
