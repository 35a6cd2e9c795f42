"""Numba kernel of the body models' forward kinematics (see occupose.body.kinematics)."""

from __future__ import annotations

import math

import numba
import numpy as np

# sin and cos: Cody-Waite reduction by pi/2 (pi/2 split in two, exact for |x| < 2**20) and
# the fdlibm minimax polynomials on [-pi/4, pi/4] (error within 2 ulp of libm); a quarter
# of libm's time here, the branch-free quadrant selection lets LLVM use vector selects.
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11
_PIO2_HI, _PIO2_LO, _INV_PIO2 = 1.57079632673412561417e+00, 6.07710050650619224932e-11, 6.36619772367581382433e-01


@numba.njit(cache=True, inline="always")
def sincos(x):
    """(sin x, cos x) of a float, |x| < 1e5."""
    k = math.floor(x * _INV_PIO2 + 0.5)
    r = (x - k * _PIO2_HI) - k * _PIO2_LO
    z = r * r
    s = r + r * z * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    c = 1.0 - 0.5 * z + z * z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    q = k - 4.0 * math.floor(0.25 * k)
    swap = (q == 1.0) | (q == 3.0)
    s_out = c if swap else s
    c_out = s if swap else c
    return (-s_out if q >= 2.0 else s_out), (-c_out if (q == 1.0) | (q == 2.0) else c_out)


#: Poses per block: the kernel runs every step on a block at once, innermost, so LLVM
#: vectorises across poses (2.3x faster than one pose at a time here).
BLOCK = 16


#: Up to this many poses the serial kernel is used: at 200 poses it took 0.07 ms here, the
#: parallel one 0.13 ms on 2 cores (waking the second thread costs more than it saves).
SERIAL_POSES = 256


@numba.njit(cache=True, parallel=True)
def points_from_poses(poses, parents, offsets, dof_node, dof_type, dof_axis, dof_sign,
                      nodes_a, offsets_a, out_a, nodes_b, offsets_b, out_b):
    """Forward kinematics of P poses, writing two sets of points attached to nodes.

    poses (P, D); parents (J,) parent-first, -1 for the root; offsets (J, 3) in the parent
    frame; per DOF (grouped by node, in node order): node, type (0 translation in the
    parent frame, 1 rotation about the node's current local axis), axis 0/1/2, sign.
    nodes_a (Ma,) and offsets_a (Ma, 3): points p[node] + R[node] @ offset written to
    out_a (P, Ma, 3); node -1 writes NaN. Same for b. Frames are rotation matrices whose
    columns are the local axes in world coordinates. Parallel over blocks of BLOCK poses.
    """
    for block in numba.prange((poses.shape[0] + BLOCK - 1) // BLOCK):
        _points_block(poses, block, parents, offsets, dof_node, dof_type, dof_axis, dof_sign,
                      nodes_a, offsets_a, out_a, nodes_b, offsets_b, out_b)


@numba.njit(cache=True)
def points_from_poses_serial(poses, parents, offsets, dof_node, dof_type, dof_axis, dof_sign,
                             nodes_a, offsets_a, out_a, nodes_b, offsets_b, out_b):
    """:func:`points_from_poses` on one thread (for few poses)."""
    for block in range((poses.shape[0] + BLOCK - 1) // BLOCK):
        _points_block(poses, block, parents, offsets, dof_node, dof_type, dof_axis, dof_sign,
                      nodes_a, offsets_a, out_a, nodes_b, offsets_b, out_b)


@numba.njit(cache=True, inline="always")
def _points_block(poses, block, parents, offsets, dof_node, dof_type, dof_axis, dof_sign,
                  nodes_a, offsets_a, out_a, nodes_b, offsets_b, out_b):
    """Block ``block`` (poses block * BLOCK onwards) of :func:`points_from_poses`."""
    num_poses, num_dofs = poses.shape
    num_nodes = parents.shape[0]
    i0 = block * BLOCK
    n = min(BLOCK, num_poses - i0)
    rot = np.empty((num_nodes, 3, 3, BLOCK))
    pos = np.empty((num_nodes, 3, BLOCK))
    values = np.zeros((num_dofs, BLOCK))
    for b in range(n):
        for d in range(num_dofs):
            values[d, b] = poses[i0 + b, d] * dof_sign[d]
    sines = np.empty(BLOCK)
    cosines = np.empty(BLOCK)
    d = 0
    for j in range(num_nodes):
        par = parents[j]
        if par < 0:
            for r in range(3):
                for b in range(BLOCK):
                    pos[j, r, b] = offsets[j, r]
                for k in range(3):
                    one = 1.0 if r == k else 0.0
                    for b in range(BLOCK):
                        rot[j, r, k, b] = one
        else:
            o0, o1, o2 = offsets[j, 0], offsets[j, 1], offsets[j, 2]
            for r in range(3):
                for b in range(BLOCK):
                    pos[j, r, b] = (pos[par, r, b] + rot[par, r, 0, b] * o0 + rot[par, r, 1, b] * o1
                                    + rot[par, r, 2, b] * o2)
                for k in range(3):
                    for b in range(BLOCK):
                        rot[j, r, k, b] = rot[par, r, k, b]
        while d < num_dofs and dof_node[d] == j:
            k = dof_axis[d]
            if dof_type[d] == 0:
                for r in range(3):
                    if par >= 0:
                        for b in range(BLOCK):
                            pos[j, r, b] += rot[par, r, k, b] * values[d, b]
                    elif r == k:
                        for b in range(BLOCK):
                            pos[j, r, b] += values[d, b]
            else:
                # right-multiply by the rotation about local axis k: columns u, v mix
                for b in range(BLOCK):
                    sines[b], cosines[b] = sincos(values[d, b])
                u = (k + 1) % 3
                v = (k + 2) % 3
                for r in range(3):
                    for b in range(BLOCK):
                        cu = rot[j, r, u, b]
                        cv = rot[j, r, v, b]
                        rot[j, r, u, b] = cosines[b] * cu + sines[b] * cv
                        rot[j, r, v, b] = cosines[b] * cv - sines[b] * cu
            d += 1
    _write_points(rot, pos, i0, n, nodes_a, offsets_a, out_a)
    _write_points(rot, pos, i0, n, nodes_b, offsets_b, out_b)


@numba.njit(cache=True, inline="always")
def _write_points(rot, pos, i0, n, nodes, offsets, out):
    """out[i0 + b, m] = pos[node] + rot[node] @ offset for the n poses of a block (NaN for node -1)."""
    for m in range(nodes.shape[0]):
        node = nodes[m]
        x0, x1, x2 = offsets[m, 0], offsets[m, 1], offsets[m, 2]
        for r in range(3):
            for b in range(n):
                if node < 0:
                    out[i0 + b, m, r] = np.nan
                else:
                    out[i0 + b, m, r] = (pos[node, r, b] + rot[node, r, 0, b] * x0 + rot[node, r, 1, b] * x1
                                         + rot[node, r, 2, b] * x2)
