"""Renderer tests: analytic depths, and the numba kernel against a slow NumPy sphere tracer."""

from types import SimpleNamespace

import numpy as np
import pytest

from occupose.camera import look_at
from occupose.geometry import primitives as prim
from occupose.synth.render import AMBIENT, Rendered, render, render_camera

W, H, F = 64, 48, 60.0
CX, CY = 31.5, 23.5


def _render(prims, pose, background=None):
    return render(prims, W, H, F, F, CX, CY, pose, background=background)


def _random_rotation(rng) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


# --- slow reference: sphere tracing of signed distances, world frame ----------------------

def _sdf(prims, k, p):
    """Signed distance (a lower bound for ellipsoids) of points p (N, 3) to primitive k."""
    kind = prims.kind[k]
    if kind == prim.ROUND_CONE:
        a, b = prims.center[k], prims.end[k]
        ra, rb = prims.size[k, :2]

        def g(s):  # distance to the sphere interpolated at s; convex in s
            return np.linalg.norm(p - (a + s[:, None] * (b - a)), axis=1) - (ra + s * (rb - ra))

        lo, hi = np.zeros(len(p)), np.ones(len(p))
        ratio = (np.sqrt(5.0) - 1.0) / 2.0
        for _ in range(50):  # golden-section search for the minimum over s in [0, 1]
            m1, m2 = hi - ratio * (hi - lo), lo + ratio * (hi - lo)
            left = g(m1) < g(m2)
            hi, lo = np.where(left, m2, hi), np.where(left, lo, m1)
        return np.minimum(np.minimum(g((lo + hi) / 2), g(np.zeros(len(p)))), g(np.ones(len(p))))
    local = (p - prims.center[k]) @ prims.axes[k]
    size = prims.size[k]
    if kind == prim.BOX:
        q = np.abs(local) - size
        return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)
    return (np.linalg.norm(local / size, axis=1) - 1.0) * size.min()


def _trace(prims, k, origin, dirs, eps=1e-10, t_max=30.0, max_iter=4000):
    """Ray length to the first hit of unit rays ``origin + t * dirs`` (inf on a miss)."""
    t = np.zeros(len(dirs))
    active = np.arange(len(dirs))
    hit = np.zeros(len(dirs), bool)
    for _ in range(max_iter):
        if not len(active):
            break
        d = _sdf(prims, k, origin + t[active, None] * dirs[active])
        done = d < eps
        hit[active[done]] = True
        t[active] += np.where(done, 0.0, d)
        active = active[~done & (t[active] < t_max)]
    return np.where(hit, t, np.inf)


def _reference(prims, pose):
    """Depth, winner index (-1 = none) and colour of every pixel, by sphere tracing."""
    u, v = np.meshgrid(np.arange(W), np.arange(H))
    cam = np.stack([(u - CX) / F, (v - CY) / F, np.ones_like(u, float)], axis=-1).reshape(-1, 3)
    length = np.linalg.norm(cam, axis=1)
    dirs = (cam / length[:, None]) @ pose[:3, :3].T
    origin = pose[:3, 3]
    depths = np.stack([_trace(prims, k, origin, dirs) / length for k in range(len(prims))])
    winner = np.where(np.isfinite(depths.min(axis=0)), depths.argmin(axis=0), -1)
    depth = np.where(winner >= 0, depths.min(axis=0), 0.0)
    color = np.zeros((len(dirs), 3), np.uint8)
    for k in range(len(prims)):
        mine = np.flatnonzero(winner == k)
        if not len(mine):
            continue
        p = origin + (depth[mine] * length[mine])[:, None] * dirs[mine]
        grad = np.stack([_sdf(prims, k, p + e) - _sdf(prims, k, p - e) for e in np.eye(3) * 1e-6], axis=1)
        cos = np.abs(np.sum(grad * dirs[mine], axis=1)) / np.linalg.norm(grad, axis=1)
        value = prims.color[k] * (AMBIENT + (1 - AMBIENT) * cos)[:, None] + 0.5
        color[mine] = np.minimum(value, 255).astype(np.uint8)
    return depth.reshape(H, W), winner.reshape(H, W), color.reshape(H, W, 3)


def _assert_matches_reference(prims, pose, depth_tol=2e-5):
    got = _render(prims, pose)
    depth, winner, color = _reference(prims, pose)
    np.testing.assert_array_equal(got.depth > 0, winner >= 0)
    np.testing.assert_allclose(got.depth, depth, atol=depth_tol, rtol=0)
    hit = winner >= 0
    np.testing.assert_array_equal(got.person[hit], prims.person[winner[hit]])
    np.testing.assert_array_equal(got.part[hit], prims.part[winner[hit]])
    assert np.all(got.person[~hit] == 0) and np.all(got.part[~hit] == 0)
    # Shading: the reference normal is a finite-difference gradient, ambiguous on box edges.
    close = np.abs(got.color.astype(int) - color).max(axis=-1) <= 2
    assert close.mean() > 0.98, close.mean()
    return got


# --- analytic depths -------------------------------------------------------------------

def test_axis_aligned_box_face_depth_is_exact():
    pose = look_at((0.0, -3.0, 1.2), (0.0, 1.0, 1.2))  # looks along +y, level
    box = prim.box((0.2, 1.0, 1.0), (0.5, 0.3, 0.4), (200, 100, 50))
    got = _render(box, pose)
    # Near face at world y = 0.7, i.e. camera z = 3.7, covering x in [-0.3, 0.7], z in [0.6, 1.4].
    for u, v in [(31, 23), (28, 30), (40, 22), (35, 32)]:
        x, y = (u - CX) / F * 3.7, (v - CY) / F * 3.7
        assert -0.3 < x < 0.7 and 0.6 < 1.2 - y < 1.4
        assert got.depth[v, u] == pytest.approx(3.7, abs=1e-3)
    assert got.depth[0, 0] == 0.0  # outside the box's image
    # Face-on: the headlight shades the face at full albedo.
    np.testing.assert_array_equal(got.color[23, 31], (200, 100, 50))


def test_sphere_depth_is_exact():
    pose = np.eye(4)  # camera frame = world frame
    center, radius = np.array([0.1, -0.05, 2.5]), 0.4
    got = render(prim.ellipsoid(center, (radius,) * 3, (90, 90, 90)), W, H, F, F, 32.0, 24.0, pose)
    assert got.depth[24, 32] > 0
    for u, v in [(32, 24), (34, 23), (30, 20), (38, 26), (36, 30)]:
        d = np.array([(u - 32.0) / F, (v - 24.0) / F, 1.0])
        b, c = d @ center, center @ center - radius**2
        disc = b * b - (d @ d) * c
        assert disc > 0
        expected = (b - np.sqrt(disc)) / (d @ d)  # ray t with d_z = 1 is camera z
        assert got.depth[v, u] == pytest.approx(expected, abs=1e-3)
    assert got.depth[0, 0] == 0.0


def test_round_cone_with_equal_radii_is_a_capsule():
    pose = np.eye(4)
    z0, r = 2.0, 0.15
    cone = prim.round_cone((-0.4, 0.0, z0), (0.4, 0.0, z0), r, r, (10, 200, 10))
    got = render(cone, W, H, F, F, 32.0, 24.0, pose)
    for u, v in [(32, 24), (40, 22), (25, 26), (32, 28)]:  # on the cylinder: |x| < 0.4 at the hit
        y = (v - 24.0) / F
        # (y t)^2 + (t - z0)^2 = r^2, nearest root
        a, b, c = 1 + y * y, -2 * z0, z0 * z0 - r * r
        t = (-b - np.sqrt(b * b - 4 * a * c)) / (2 * a)
        assert abs((u - 32.0) / F * t) < 0.4
        assert got.depth[v, u] == pytest.approx(t, abs=1e-3)
    for u, v in [(45, 24), (19, 23)]:  # on the end caps: |x| > 0.4
        d = np.array([(u - 32.0) / F, (v - 24.0) / F, 1.0])
        c_end = np.array([0.4 if u > 32 else -0.4, 0.0, z0])
        bb, cc = d @ c_end, c_end @ c_end - r * r
        t = (bb - np.sqrt(bb * bb - (d @ d) * cc)) / (d @ d)
        assert abs(d[0] * t) > 0.4
        assert got.depth[v, u] == pytest.approx(t, abs=1e-3)


def test_floor_reaching_behind_the_camera():
    # A level camera 1.6 m above a large floor slab that extends behind it.
    pose = look_at((0.0, 0.0, 1.6), (0.0, 5.0, 1.6))
    floor = prim.box((0.0, 0.0, -0.05), (20.0, 20.0, 0.05), (120, 120, 120))
    got = _render(floor, pose)
    y = (np.arange(H) - CY) / F
    expected = 1.6 / np.where(y > 0, y, np.inf)  # plane z = 0 seen at camera z = 1.6 / y
    expected[expected > 20.0] = 0.0  # rows beyond the slab's far edge (y = 20) see nothing
    assert np.count_nonzero(expected) > 10
    for u in (0, 17, 63):
        np.testing.assert_allclose(got.depth[:, u], expected, atol=1e-4)


def test_camera_inside_a_box_sees_its_walls():
    room = prim.box((0.0, 0.0, 1.5), (3.0, 2.0, 1.5), (200, 200, 200))
    pose = look_at((0.0, 0.0, 1.5), (1.0, 0.0, 1.5))
    got = _render(room, pose)
    assert np.all(got.depth > 0)
    # The wall at x = 3 fills the centre of the view at camera z = 3.
    np.testing.assert_allclose(got.depth[14:34, 12:52], 3.0, atol=1e-5)
    dome = prim.ellipsoid((0.0, 0.0, 1.5), (5.0, 5.0, 5.0), (200, 200, 200))
    inside = _render(dome, pose)
    length = np.sqrt(1 + ((np.arange(W) - CX) / F) ** 2 + ((np.arange(H)[:, None] - CY) / F) ** 2)
    np.testing.assert_allclose(inside.depth, 5.0 / length, rtol=1e-6)  # ray length 5 everywhere


# --- against the sphere-tracing reference ------------------------------------------------

@pytest.mark.parametrize("a, b, ra, rb", [
    ((-0.3, 0.2, 2.2), (0.3, -0.1, 2.6), 0.25, 0.08),   # tapered, oblique
    ((0.0, 0.3, 2.0), (0.1, -0.3, 2.4), 0.05, 0.3),     # widening towards b
    ((0.0, 0.0, 2.0), (0.05, 0.02, 3.0), 0.3, 0.1),     # axis along the view direction
    ((0.0, 0.0, 3.0), (0.05, 0.02, 2.0), 0.3, 0.1),     # the same, big end far
    ((-0.1, 0.0, 2.5), (0.12, 0.05, 2.5), 0.3, 0.12),   # nearly one sphere inside the other
    ((-0.1, 0.0, 2.5), (0.0, 0.05, 2.5), 0.3, 0.12),    # small sphere inside the big one
])
def test_round_cone_matches_reference(a, b, ra, rb):
    cone = prim.round_cone(a, b, ra, rb, (200, 80, 30), person=1, part=4)
    _assert_matches_reference(cone, np.eye(4))


def test_random_round_cones_match_reference():
    rng = np.random.default_rng(7)
    for _ in range(3):
        a = rng.uniform((-0.5, -0.4, 1.5), (0.5, 0.4, 3.0))
        b = a + rng.normal(scale=0.4, size=3)
        ra, rb = rng.uniform(0.03, 0.3, size=2)
        got = _assert_matches_reference(prim.round_cone(a, b, ra, rb, (30, 60, 200)), np.eye(4))
        assert np.count_nonzero(got.depth) > 100


def test_rotated_box_and_ellipsoid_match_reference():
    rng = np.random.default_rng(3)
    pose = look_at((-1.0, -3.0, 2.0), (0.0, 0.0, 1.0))
    shapes = prim.concat([
        prim.box((0.4, 0.2, 1.0), (0.5, 0.3, 0.2), (200, 150, 100), _random_rotation(rng), person=2, part=7),
        prim.ellipsoid((-0.5, 0.0, 1.2), (0.4, 0.2, 0.3), (100, 200, 150), _random_rotation(rng), person=3, part=9),
    ])
    _assert_matches_reference(shapes, pose)


def test_random_scene_matches_reference():
    rng = np.random.default_rng(11)
    pose = look_at((0.5, -4.0, 1.8), (0.0, 0.0, 1.0))
    batch = []
    for i in range(9):
        center = rng.uniform((-1.0, -1.0, 0.3), (1.0, 1.0, 1.8))
        color = rng.integers(30, 255, size=3)
        kind = i % 3
        if kind == prim.BOX:
            batch.append(prim.box(center, rng.uniform(0.05, 0.4, 3), color, _random_rotation(rng), person=i, part=i))
        elif kind == prim.ELLIPSOID:
            batch.append(prim.ellipsoid(center, rng.uniform(0.05, 0.4, 3), color, _random_rotation(rng),
                                        person=i, part=i))
        else:
            end = center + rng.normal(scale=0.3, size=3)
            batch.append(prim.round_cone(center, end, *rng.uniform(0.03, 0.2, 2), color, person=i, part=i))
    scene = prim.concat(batch)
    got = _assert_matches_reference(scene, pose)
    assert len(np.unique(got.person)) >= 6  # most primitives are visible: a real overlap test


# --- labels, z-order, background ---------------------------------------------------------

def test_labels_and_colour_come_from_the_hit_primitive():
    pose = np.eye(4)
    scene = prim.concat([
        prim.box((-0.5, 0.0, 3.0), (0.3, 0.3, 0.3), (255, 0, 0), person=0, part=0),
        prim.ellipsoid((0.5, 0.0, 3.0), (0.3, 0.3, 0.3), (0, 255, 0), person=4, part=2),
    ])
    got = _render(scene, pose)
    left, right = got.depth[:, : W // 2] > 0, got.depth[:, W // 2:] > 0
    assert left.any() and right.any()
    assert np.all(got.person[:, W // 2:][right] == 4) and np.all(got.part[:, W // 2:][right] == 2)
    assert np.all(got.person[:, : W // 2] == 0) and np.all(got.part[:, : W // 2] == 0)
    assert np.all(got.color[:, W // 2:][right][:, [0, 2]] == 0)  # pure green albedo stays green
    assert np.all(got.color[:, : W // 2][left][:, [1, 2]] == 0)
    assert np.all(got.color[got.depth == 0] == 0)


@pytest.mark.parametrize("near_first", [True, False])
def test_nearest_primitive_wins(near_first):
    near = prim.ellipsoid((0.0, 0.0, 2.0), (0.2, 0.2, 0.2), (0, 0, 255), person=1, part=1)
    far = prim.box((0.2, 0.0, 3.0), (0.5, 0.5, 0.1), (255, 0, 0), person=2, part=3)
    scene = prim.concat([near, far] if near_first else [far, near])
    got = render(scene, W, H, F, F, 32.0, 24.0, np.eye(4))
    assert got.person[24, 32] == 1 and got.depth[24, 32] == pytest.approx(1.8, abs=1e-6)
    assert got.person[24, 44] == 2 and got.depth[24, 44] == pytest.approx(2.9, abs=1e-6)


def test_background_render_equals_rendering_everything():
    rng = np.random.default_rng(5)
    pose = look_at((2.0, -3.0, 2.2), (0.0, 0.0, 0.8))
    static = prim.concat([
        prim.box((0.0, 0.0, -0.05), (3.0, 3.0, 0.05), (150, 140, 120)),
        prim.box((0.0, 3.05, 1.4), (3.0, 0.05, 1.4), (210, 210, 200)),
        prim.box((0.6, 0.5, 0.4), (0.4, 0.3, 0.4), (140, 100, 60), axes=_random_rotation(rng)),
    ])
    moving = prim.concat([
        prim.round_cone((0.0, -0.2, 0.1), (0.0, -0.2, 0.9), 0.08, 0.12, (40, 60, 120), person=1, part=10),
        prim.ellipsoid((0.0, -0.2, 1.3), (0.2, 0.15, 0.3), (40, 60, 120), person=1, part=2),
        prim.box((0.5, 0.4, 0.9), (0.1, 0.3, 0.1), (200, 20, 20), person=2, part=6),  # cuts into the furniture
    ])
    background = _render(static, pose)
    saved = [a.copy() for a in (background.depth, background.color, background.person, background.part)]
    layered = _render(moving, pose, background=background)
    at_once = _render(prim.concat([static, moving]), pose)
    for name in ("depth", "color", "person", "part"):
        np.testing.assert_array_equal(getattr(layered, name), getattr(at_once, name))
    for before, after in zip(saved, (background.depth, background.color, background.person, background.part)):
        np.testing.assert_array_equal(before, after)
    assert set(np.unique(layered.person)) == {0, 1, 2}


def test_render_camera_reads_any_camera_like_object():
    pose = look_at((0.0, -3.0, 1.0), (0.0, 0.0, 1.0))
    scene = prim.ellipsoid((0.0, 0.0, 1.0), (0.3, 0.3, 0.5), (120, 130, 140), person=1, part=1)
    camera = SimpleNamespace(width=W, height=H, fx=F, fy=F, cx=CX, cy=CY, world_from_camera=pose)
    a, b = render_camera(scene, camera), _render(scene, pose)
    np.testing.assert_array_equal(a.depth, b.depth)
    np.testing.assert_array_equal(a.color, b.color)
    with pytest.raises(ValueError, match="world_from_camera"):
        render_camera(scene, SimpleNamespace(width=W, height=H, fx=F, fy=F, cx=CX, cy=CY))


def test_empty_batch_and_primitives_behind_the_camera():
    got = _render(prim.concat([]), np.eye(4))
    assert got.depth.shape == (H, W) and not got.depth.any() and got.color.shape == (H, W, 3)
    behind = prim.box((0.0, 0.0, -2.0), (0.5, 0.5, 0.5), (255, 255, 255))
    assert not _render(behind, np.eye(4)).depth.any()


def test_bad_input_is_rejected():
    ball = prim.ellipsoid((0.0, 0.0, 2.0), (0.2, 0.2, 0.2), (1, 2, 3))
    with pytest.raises(ValueError, match="world_from_camera"):
        render(ball, W, H, F, F, CX, CY, np.eye(3))
    with pytest.raises(ValueError, match="rigid"):
        render(ball, W, H, F, F, CX, CY, np.diag([2.0, 1.0, 1.0, 1.0]))
    with pytest.raises(ValueError, match="width"):
        render(ball, 0, H, F, F, CX, CY, np.eye(4))
    with pytest.raises(ValueError, match="fx"):
        render(ball, W, H, -1.0, F, CX, CY, np.eye(4))
    with pytest.raises(ValueError, match="orthonormal"):
        _render(prim.box((0, 0, 2), (0.1, 0.1, 0.1), (1, 1, 1), axes=np.diag([1.0, 2.0, 1.0])), np.eye(4))
    with pytest.raises(ValueError, match="size"):
        _render(prim.round_cone((0, 0, 2), (0, 0, 3), 0.1, -0.1, (1, 1, 1)), np.eye(4))
    with pytest.raises(ValueError, match="Primitives"):
        _render("not primitives", np.eye(4))
    small = Rendered(np.zeros((2, 2), np.float32), np.zeros((2, 2, 3), np.uint8),
                     np.zeros((2, 2), np.uint16), np.zeros((2, 2), np.uint8))
    with pytest.raises(ValueError, match="background.depth"):
        _render(ball, np.eye(4), background=small)
