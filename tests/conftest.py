"""Shared test fixtures. Tests that need ../shared/data are marked ``shared`` and skip without it."""

import numpy as np
import pytest

from occupose.paths import mocap_dir


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


@pytest.fixture
def mocap():
    """Path of the shared mocap folder; skips the test when the shared data is absent."""
    path = mocap_dir()
    if path is None:
        pytest.skip("shared mocap data (../shared/data/mocap or OCCUPOSE_DATA) not present")
    return path
