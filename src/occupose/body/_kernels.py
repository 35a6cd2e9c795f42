"""Numba kernel of the body models' forward kinematics (see occupose.body.kinematics)."""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, parallel=True, fastmath=False)
def points_from_poses(poses, parents, offsets, dof_node, dof_type, dof_axis, dof_sign,
                      nodes_a, offsets_a, out_a, nodes_b, offsets_b, out_b):
    """Forward kinematics of P poses, writing two sets of points attached to nodes.

    poses (P, D); parents (J,) parent-first, -1 for the root; offsets (J, 3) in the parent
    frame; per DOF (grouped by node, in node order): node, type (0 translation in the
    parent frame, 1 rotation about the node's current local axis), axis 0/1/2, sign.
    nodes_a (Ma,) and offsets_a (Ma, 3): points p[node] + R[node] @ offset written to
    out_a (P, Ma, 3); node -1 writes NaN. Same for b. Frames are rotation matrices whose
    columns are the local axes in world coordinates.
    """
    num_poses, num_dofs = poses.shape
    num_nodes = parents.shape[0]
    for i in numba.prange(num_poses):
        rot = np.empty((num_nodes, 3, 3))
        pos = np.empty((num_nodes, 3))
        d = 0
        for j in range(num_nodes):
            par = parents[j]
            if par < 0:
                for r in range(3):
                    pos[j, r] = offsets[j, r]
                    for c in range(3):
                        rot[j, r, c] = 1.0 if r == c else 0.0
            else:
                for r in range(3):
                    pos[j, r] = (pos[par, r] + rot[par, r, 0] * offsets[j, 0] + rot[par, r, 1] * offsets[j, 1]
                                 + rot[par, r, 2] * offsets[j, 2])
                    for c in range(3):
                        rot[j, r, c] = rot[par, r, c]
            while d < num_dofs and dof_node[d] == j:
                value = poses[i, d] * dof_sign[d]
                k = dof_axis[d]
                if dof_type[d] == 0:
                    if par < 0:
                        pos[j, k] += value
                    else:
                        for r in range(3):
                            pos[j, r] += rot[par, r, k] * value
                else:
                    # right-multiply by the rotation about local axis k: columns u, v mix
                    u = (k + 1) % 3
                    v = (k + 2) % 3
                    c = math.cos(value)
                    s = math.sin(value)
                    for r in range(3):
                        cu = rot[j, r, u]
                        cv = rot[j, r, v]
                        rot[j, r, u] = c * cu + s * cv
                        rot[j, r, v] = c * cv - s * cu
                d += 1
        for m in range(nodes_a.shape[0]):
            n = nodes_a[m]
            for r in range(3):
                if n < 0:
                    out_a[i, m, r] = np.nan
                else:
                    out_a[i, m, r] = (pos[n, r] + rot[n, r, 0] * offsets_a[m, 0] + rot[n, r, 1] * offsets_a[m, 1]
                                      + rot[n, r, 2] * offsets_a[m, 2])
        for m in range(nodes_b.shape[0]):
            n = nodes_b[m]
            for r in range(3):
                if n < 0:
                    out_b[i, m, r] = np.nan
                else:
                    out_b[i, m, r] = (pos[n, r] + rot[n, r, 0] * offsets_b[m, 0] + rot[n, r, 1] * offsets_b[m, 1]
                                      + rot[n, r, 2] * offsets_b[m, 2])
