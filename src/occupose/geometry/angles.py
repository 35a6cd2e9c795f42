"""Angles: wrapping into [-pi, pi)."""

from __future__ import annotations

import math


def wrap_angle(angles):
    """``angles`` (radians: a float or an array) taken into [-pi, pi) by whole turns:
    ``(angles + pi) mod 2 pi - pi``, of the same kind as given."""
    return (angles + math.pi) % (2.0 * math.pi) - math.pi
