"""Fixtures of the Python tests."""
import os

import pytest


@pytest.fixture
def api_trace() -> str:
    path = os.environ.get("KAGE_API_TRACE")
    if not path or not os.path.exists(path):
        pytest.fail("KAGE_API_TRACE must name the kage_api_trace binary (CTest sets it)")
    return path


@pytest.fixture
def kagec() -> str:
    path = os.environ.get("KAGEC")
    if not path or not os.path.exists(path):
        pytest.fail("KAGEC must name the kagec binary (CTest sets it)")
    return path
