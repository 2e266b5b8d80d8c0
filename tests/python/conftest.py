"""Fixtures of the Python tests."""
import os

import pytest


def built_binary(variable: str, name: str) -> str:
    """The path of a binary of the build that CTest passes in `variable`."""
    path = os.environ.get(variable)
    if not path or not os.path.exists(path):
        pytest.fail(f"{variable} must name the {name} binary (CTest sets it)")
    return path


@pytest.fixture
def api_trace() -> str:
    return built_binary("KAGE_API_TRACE", "kage_api_trace")


@pytest.fixture
def kagec() -> str:
    return built_binary("KAGEC", "kagec")
