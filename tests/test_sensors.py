"""Tests of occupose.sensors: the depth noise of each sensor model, as stated in the literature."""

import numpy as np
import pytest

from occupose.sensors import depth_std


def test_stated_std_values():
    assert depth_std(2.0, "structured_light") == pytest.approx(0.0012 + 0.0019 * 1.6**2)
    assert depth_std(2.0, "tof") == pytest.approx(0.0017)
    assert depth_std(3.0, "none") == 0.0
    z = np.linspace(0.5, 3.86, 50)
    assert np.all(depth_std(z, "tof") <= 0.017)  # the Azure Kinect's specified random error
    assert depth_std(z, "structured_light").shape == z.shape
    with pytest.raises(ValueError, match="valid names"):
        depth_std(1.0, "lidar")
