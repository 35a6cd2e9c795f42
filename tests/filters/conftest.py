"""Toy problems with known answers, shared by the filter tests (as fixtures: test modules
cannot import each other).

- ``random_walk``: a 1-D random walk observed with Gaussian noise (the Kalman posterior);
- ``separable``: parts scored on their own DOFs, or along a kinematic chain;
- ``shared_score``: ``separable`` with every part given the total score;
- ``heading``: one full-turn angle observed near the +-pi seam;
- ``groups``: partitions / weight groups from (dofs, parts) pairs.
"""

from dataclasses import dataclass

import numpy as np
import pytest


@dataclass
class Group:
    dofs: np.ndarray
    parts: np.ndarray


def _groups(*pairs):
    return [Group(np.asarray(d), np.asarray(p)) for d, p in pairs]


class RandomWalk1D:
    """x_t = x_{t-1} + N(0, q^2), y_t = x_t + N(0, r^2): the Kalman filter gives the exact posterior."""

    def __init__(self, q, r):
        self.num_dofs = 1
        self.limits = np.array([[-np.inf, np.inf]])
        self.angular = np.array([False])
        self.diffusion = np.array([q])
        self.partitions = self.weight_groups = _groups(([0], [0]))
        self.r = r
        self.y = 0.0

    def log_likelihood(self, poses):
        return -0.5 * ((poses[:, :1] - self.y) / self.r) ** 2


class Separable:
    """G parts of ``width`` DOFs each; part k's log-likelihood depends on its own DOFs only.

    Partitions and weight groups are the parts; ``chain`` makes part k's point the sum of the
    DOF blocks 0..k (a kinematic chain: the child's score depends on its parent's DOFs).
    """

    def __init__(self, num_parts, width, sigma=0.1, step=0.05, chain=False, seed=0):
        d = num_parts * width
        self.num_dofs = d
        self.limits = np.tile([-5.0, 5.0], (d, 1))
        self.angular = np.zeros(d, bool)
        self.diffusion = np.full(d, step)
        blocks = np.arange(d).reshape(num_parts, width)
        self.partitions = self.weight_groups = _groups(*[(b, [k]) for k, b in enumerate(blocks)])
        self.blocks, self.sigma, self.chain = blocks, sigma, chain
        self.target = np.random.default_rng(seed).uniform(-1, 1, d)
        self.calls = 0

    def points(self, poses):
        parts = poses[:, self.blocks]  # (P, G, width)
        return np.cumsum(parts, axis=1) if self.chain else parts

    def log_likelihood(self, poses):
        self.calls += 1
        goal = self.points(self.target[None])[0]
        return -0.5 * (((self.points(poses) - goal) / self.sigma) ** 2).sum(axis=2)


class Heading:
    """One full-turn angle observed through a von Mises likelihood centred near the +-pi seam."""

    num_dofs = 1
    limits = np.array([[-np.pi, np.pi]])
    angular = np.array([True])
    diffusion = np.array([0.2])
    partitions = weight_groups = _groups(([0], [0]))
    target = np.pi - 0.05

    def log_likelihood(self, poses):
        return 50.0 * np.cos(poses - self.target)


class SharedScore(Separable):
    """Every part gets the same column (the total score): the groups' weights are identical."""

    def log_likelihood(self, poses):
        total = super().log_likelihood(poses).sum(axis=1, keepdims=True)
        return np.repeat(total, len(self.blocks), axis=1)


@pytest.fixture
def groups():
    """groups(*(dofs, parts)) -> a list of Group."""
    return _groups


@pytest.fixture
def random_walk():
    """The RandomWalk1D class: random_walk(q, r)."""
    return RandomWalk1D


@pytest.fixture
def separable():
    """The Separable class: separable(num_parts, width, sigma=0.1, step=0.05, chain=False, seed=0)."""
    return Separable


@pytest.fixture
def shared_score():
    """The SharedScore class (Separable arguments)."""
    return SharedScore


@pytest.fixture
def heading():
    """The Heading class: heading() is the problem, heading.target its answer."""
    return Heading
