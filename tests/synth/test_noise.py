"""The generator's sensor noise: measured statistics against the formulas of occupose.sensors,
shadows, edges, seeds."""

import numpy as np
import pytest

from occupose.geometry import primitives as prim
from occupose.sensors import depth_std

from occupose.synth.noise import (
    KINECT_V1_INVERSE_DEPTH_OFFSET, KINECT_V1_INVERSE_DEPTH_STEP, NOISE_MODELS, apply_noise,
)
from occupose.synth.render import render

FX = 525.0


# --- slow NumPy references of the kernels (same draws from an identically seeded rng) -----

def _reference_shadows(z, fx_baseline):
    """Pixels whose projector coordinate u - fx_baseline / z breaks the row order."""
    if fx_baseline < 0:
        return _reference_shadows(z[:, ::-1], -fx_baseline)[:, ::-1]
    valid = z > 0
    projector_u = np.where(valid, np.arange(z.shape[1]) - fx_baseline / np.where(valid, z, 1.0), np.inf)
    right_min = np.full_like(projector_u, np.inf)  # smallest coordinate strictly to the right
    right_min[:, :-1] = np.minimum.accumulate(projector_u[:, :0:-1], axis=1)[:, ::-1]
    return valid & (projector_u > right_min)


def _reference_structured_light(z, rng, fx_baseline, min_range, max_range):
    measured = (z > 0) & ~_reference_shadows(z, fx_baseline) & (z >= min_range) & (z <= max_range)
    zm = z[measured]
    noise = rng.standard_normal(len(zm))
    step, offset = KINECT_V1_INVERSE_DEPTH_STEP, KINECT_V1_INVERSE_DEPTH_OFFSET
    std_raw = depth_std(zm, "structured_light") / (step * zm**2)
    raw = np.floor((offset - 1.0 / zm) / step + np.sqrt(np.maximum(std_raw**2 - 1 / 12, 0)) * noise + 0.5)
    out = np.zeros(z.shape, np.float32)
    out[measured] = 1.0 / (offset - step * raw)
    return out


def _reference_tof(z, rng, flying_fraction, edge_jump, min_range, max_range):
    padded = np.pad(z, 1)
    jump, other = np.zeros_like(z), z.copy()
    for neighbour in (padded[:-2, 1:-1], padded[2:, 1:-1], padded[1:-1, :-2], padded[1:-1, 2:]):
        larger = (neighbour > 0) & (np.abs(neighbour - z) > jump)
        jump, other = np.where(larger, np.abs(neighbour - z), jump), np.where(larger, neighbour, other)
    edge = (z > 0) & (jump > edge_jump)
    draws = rng.random((np.count_nonzero(edge), 2))
    flies = np.flatnonzero(edge)[draws[:, 0] < flying_fraction]  # row-major order, as drawn
    share = draws[draws[:, 0] < flying_fraction, 1]
    mixed = z.copy().reshape(-1)
    mixed[flies] += share * (other.reshape(-1)[flies] - mixed[flies])
    mixed = mixed.reshape(z.shape)
    measured = (z > 0) & (z >= min_range) & (z <= max_range)
    m = mixed[measured]
    value = m + depth_std(m, "tof") * rng.standard_normal(len(m))
    out = np.zeros(z.shape, np.float32)
    out[measured] = np.where(value > 0, value, 0.0)
    return out


def _random_depth(rng, shape=(40, 60)):
    """Piecewise-flat depth with steps, holes and out-of-range pixels."""
    depth = np.repeat(np.repeat(rng.uniform(0.3, 5.5, size=(shape[0] // 4, shape[1] // 6)), 4, 0), 6, 1)
    depth += rng.normal(scale=0.01, size=shape)
    depth[rng.random(shape) < 0.05] = 0.0
    return depth


@pytest.mark.parametrize("baseline", [0.075, -0.05])
def test_structured_light_kernel_matches_reference(baseline):
    depth = _random_depth(np.random.default_rng(20))
    got = apply_noise(depth, "structured_light", np.random.default_rng(21), fx=FX, baseline=baseline, dropout=0.0)
    expected = _reference_structured_light(depth, np.random.default_rng(21), FX * baseline, 0.5, 5.0)
    np.testing.assert_array_equal(got, expected)
    assert 0 < np.count_nonzero(_reference_shadows(depth, FX * baseline))


def test_tof_kernel_matches_reference():
    depth = _random_depth(np.random.default_rng(22))
    got = apply_noise(depth, "tof", np.random.default_rng(23), flying_fraction=0.6, edge_jump=0.05, dropout=0.0)
    expected = _reference_tof(depth, np.random.default_rng(23), 0.6, 0.05, 0.5, 4.5)
    np.testing.assert_array_equal(got, expected)


# --- behaviour ---------------------------------------------------------------------------

def _step_image(near=1.5, far=3.0, cols=(200, 300), shape=(60, 400)):
    """A wall at ``far`` with a foreground slab at ``near`` over columns [cols[0], cols[1])."""
    depth = np.full(shape, far, np.float32)
    depth[:, cols[0]:cols[1]] = near
    return depth


@pytest.mark.parametrize("model", ["structured_light", "tof"])
@pytest.mark.parametrize("z", [2.0, 4.0])
def test_flat_wall_std_matches_the_stated_formula(model, z):
    wall = np.full((240, 320), z, np.float32)
    noisy = apply_noise(wall, model, np.random.default_rng(1), fx=FX)
    measured = noisy[noisy > 0].std()
    assert measured == pytest.approx(depth_std(z, model), rel=0.2)
    assert abs(noisy[noisy > 0].mean() - z) < 0.5 * depth_std(z, model)  # no gross bias


def test_structured_light_is_quantised_in_raw_disparity_units():
    rng = np.random.default_rng(2)
    depth = rng.uniform(0.6, 4.5, size=(50, 50)).astype(np.float32)
    noisy = apply_noise(depth, "structured_light", rng, fx=FX, shadows=False, dropout=0.0)
    raw = (KINECT_V1_INVERSE_DEPTH_OFFSET - 1.0 / noisy.astype(np.float64)) / KINECT_V1_INVERSE_DEPTH_STEP
    np.testing.assert_allclose(raw, np.round(raw), atol=1e-3)  # float32 storage rounding only
    # So the depth step between neighbouring levels is about 0.00307 z^2 (1.2 cm at 2 m).
    levels = np.sort(np.unique(apply_noise(np.full((100, 100), 2.0), "structured_light", rng, fx=FX)))
    levels = levels[levels > 0]
    assert np.diff(levels).min() == pytest.approx(0.00307 * 4, rel=0.05)


def test_rendered_ball_casts_its_shadow_on_its_left():
    scene = prim.concat([
        prim.box((0.0, 0.0, 3.1), (3.0, 3.0, 0.1), (200, 200, 200)),   # wall at z = 3
        prim.ellipsoid((0.0, 0.0, 1.5), (0.2, 0.2, 0.2), (200, 0, 0), person=1),
    ])
    fx = 140.0
    ideal = render(scene, 160, 120, fx, fx, 79.5, 59.5, np.eye(4))
    noisy = apply_noise(ideal.depth, "structured_light", np.random.default_rng(9), fx=fx, dropout=0.0)
    shadow = (noisy == 0) & (ideal.depth > 0)
    assert shadow.sum() > 20
    band = fx * 0.075 * (1 / 1.3 - 1 / 3.0) + 1  # widest where the ball is nearest
    for v in np.flatnonzero(shadow.any(axis=1)):
        ball = np.flatnonzero(ideal.person[v])
        cols = np.flatnonzero(shadow[v])
        assert len(ball) and cols.max() < ball.min() and cols.min() > ball.min() - band


@pytest.mark.parametrize("baseline", [0.075, -0.075])
def test_projector_shadows_fall_beside_the_foreground(baseline):
    depth = _step_image()
    noisy = apply_noise(depth, "structured_light", np.random.default_rng(3), fx=FX, baseline=baseline, dropout=0.0)
    width = FX * abs(baseline) * (1 / 1.5 - 1 / 3.0)  # 13.1 pixels
    band = int(np.floor(width))
    if baseline > 0:  # projector to the right: shadow left of the slab
        shadow, lit = noisy[:, 200 - band:200], noisy[:, 300:300 + 2 * band]
        outside = noisy[:, 200 - band - 3:200 - band]
    else:
        shadow, lit = noisy[:, 300:300 + band], noisy[:, 200 - 2 * band:200]
        outside = noisy[:, 300 + band:300 + band + 3]
    assert np.all(shadow == 0)
    assert np.all(lit > 0) and np.all(outside > 0)
    assert np.all(noisy[:, 200:300] > 0)  # the slab itself is lit
    assert np.count_nonzero(noisy == 0) == shadow.size


def test_tof_flying_pixels_only_at_depth_edges():
    depth = _step_image(near=1.5, far=3.0)
    noisy = apply_noise(depth, "tof", np.random.default_rng(4), flying_fraction=1.0, dropout=0.0)
    sigma = depth_std(3.0, "tof")
    between = (noisy > 1.5 + 5 * sigma) & (noisy < 3.0 - 5 * sigma)
    cols = np.flatnonzero(between.any(axis=0))
    assert set(cols) <= {199, 200, 299, 300}
    assert between[:, [199, 200, 299, 300]].mean() > 0.8  # all mixed; a few mix very little
    # Away from the edges only Gaussian noise.
    far = np.r_[0:198, 302:400]
    assert np.all(np.abs(noisy[:, far] - depth[:, far]) < 6 * sigma)
    none = apply_noise(depth, "tof", np.random.default_rng(4), flying_fraction=0.0, dropout=0.0)
    assert not ((none > 1.5 + 5 * sigma) & (none < 3.0 - 5 * sigma)).any()


def test_out_of_range_and_dropouts_become_invalid():
    rng = np.random.default_rng(5)
    assert not apply_noise(np.full((20, 20), 4.8), "tof", rng).any()  # beyond 4.5 m
    assert not apply_noise(np.full((20, 20), 0.3), "structured_light", rng, fx=FX).any()  # too near
    wall = np.full((300, 300), 2.0)
    lost = apply_noise(wall, "tof", rng, dropout=0.1) == 0
    assert lost.mean() == pytest.approx(0.1, abs=0.01)


@pytest.mark.parametrize("model", sorted(NOISE_MODELS))
def test_invalid_pixels_stay_invalid(model):
    rng = np.random.default_rng(6)
    depth = rng.uniform(1.0, 3.0, size=(80, 90))
    holes = rng.random(depth.shape) < 0.2
    depth[holes] = 0.0
    noisy = apply_noise(depth, model, rng, fx=FX)
    assert noisy.dtype == np.float32 and noisy.shape == depth.shape
    assert np.all(noisy[holes] == 0) and np.all(np.isfinite(noisy)) and np.all(noisy >= 0)


@pytest.mark.parametrize("model", sorted(NOISE_MODELS))
def test_same_seed_same_output(model):
    depth = _step_image()
    a = apply_noise(depth, model, np.random.default_rng(7), fx=FX)
    b = apply_noise(depth, model, np.random.default_rng(7), fx=FX)
    np.testing.assert_array_equal(a, b)
    c = apply_noise(depth, model, np.random.default_rng(8), fx=FX)
    if model == "none":
        np.testing.assert_array_equal(a, depth)
    else:
        assert not np.array_equal(a, c)


def test_bad_input_is_rejected():
    rng = np.random.default_rng(0)
    wall = np.full((10, 10), 2.0)
    with pytest.raises(ValueError, match="structured_light"):
        apply_noise(wall, "kinect", rng)
    with pytest.raises(ValueError, match="flying_fraction"):
        apply_noise(wall, "structured_light", rng, fx=FX, flying_fraction=0.2)
    with pytest.raises(ValueError, match="fx"):
        apply_noise(wall, "structured_light", rng)
    with pytest.raises(ValueError, match="Generator"):
        apply_noise(wall, "tof", 42)
    with pytest.raises(ValueError, match="Generator"):
        apply_noise(wall, "none", None)
    with pytest.raises(ValueError, match="2-D"):
        apply_noise(np.ones(5), "tof", rng)
    with pytest.raises(ValueError, match="finite"):
        apply_noise(np.full((3, 3), np.nan), "none", rng)
    with pytest.raises(ValueError, match="dropout"):
        apply_noise(wall, "tof", rng, dropout=1.5)


# --- errors beyond the nominal models (the randomized scenes' worse sensors) ---------------

def test_sensor_errors_add_noise_bias_and_patchy_dropouts_on_dark_people():
    rng = np.random.default_rng(3)
    depth = np.full((240, 320), 2.0)
    depth[:, :10] = 0.0                                  # no measurement stays none
    person = np.zeros(depth.shape, np.uint16)
    person[40:200, 100:180] = 1                          # a dark person
    person[40:200, 200:280] = 2                          # and one in other clothes
    out = apply_noise(depth, "none", rng, person=person, extra_std=0.01, bias=0.011, bias_scale=0.001,
                      body_dropout=0.3, dark_people=(1,))
    assert np.all(out[:, :10] == 0)
    other = out[person == 2]
    assert np.all(other > 0)
    assert other.mean() == pytest.approx(2.0 + 0.011 + 0.002, abs=1e-3)
    assert other.std() == pytest.approx(0.01, rel=0.05)
    dark = out[40:200, 100:180]
    assert np.mean(dark == 0) == pytest.approx(0.3, abs=0.01)
    # in patches: a lost pixel's right neighbour is lost far more often than 30 % of the time
    lost = dark == 0
    assert np.mean(lost[:, 1:][lost[:, :-1]]) > 0.8


def test_sensor_errors_default_to_nothing_and_refuse_bad_options():
    depth = np.full((20, 30), 1.5)
    plain = apply_noise(depth, "tof", np.random.default_rng(1))
    same = apply_noise(depth, "tof", np.random.default_rng(1), extra_std=0.0, bias=0.0, body_dropout=0.0)
    assert np.array_equal(plain, same)
    with pytest.raises(ValueError, match="body_dropout needs the person image"):
        apply_noise(depth, "none", np.random.default_rng(1), body_dropout=0.2, dark_people=(1,))
    with pytest.raises(ValueError, match="extra_std must be >= 0"):
        apply_noise(depth, "none", np.random.default_rng(1), extra_std=-0.01)
