import math

import numpy as np
import pytest

from occupose.geometry.angles import wrap_angle


def test_wrap_angle_takes_whole_turns_into_minus_pi_to_pi():
    angles = np.array([0.0, 3.0, 3.5, -3.5, 7.0, -7.0, math.pi, -math.pi, 100.0])
    wrapped = wrap_angle(angles)
    assert np.all((wrapped >= -math.pi) & (wrapped < math.pi))
    turns = (angles - wrapped) / (2 * math.pi)
    np.testing.assert_allclose(turns, np.round(turns), atol=1e-12)  # moved by whole turns only
    assert wrapped[1] == 3.0 and wrapped[2] == pytest.approx(3.5 - 2 * math.pi)
    assert wrapped[6] == -math.pi and wrapped[7] == -math.pi  # pi goes to -pi, -pi stays
    assert isinstance(wrap_angle(3.5), float) and wrap_angle(-3.5) == pytest.approx(2 * math.pi - 3.5)
