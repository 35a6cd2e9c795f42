"""Postures of the body models in their own DOFs: how a person stands at rest.

Angles follow :mod:`occupose.body.model` (radians).
"""

from __future__ import annotations

import numpy as np

#: Arms hanging relaxed: shoulder flex, abd, rot, elbow (radians).
ARM_REST = np.array([0.0, 0.12, 0.0, 0.15])
