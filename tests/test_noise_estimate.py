"""Sensor noise from the data: the estimate of a camera's depth noise from its static pixels,
the tolerant match of a camera with a sensor preset, and the grid's ``measured`` noise model."""

import dataclasses
import json

import numpy as np
import pytest

from occupose.camera import CAMERA_PRESETS, camera_preset, look_at, matching_preset
from occupose.config import GridConfig, TrackerConfig
from occupose.grid.noise import camera_noise, measure_noise
from occupose.sensors import NoiseEstimate, depth_std, estimate_depth_noise
from occupose.synth.generate import frames
from occupose.synth.noise import tof_noise
from occupose.synth.render import render_camera
from occupose.synth.scenarios import build_scenario
from occupose.synth.scene import cabinet, concat, room, table

NUM_FRAMES = 20


def _static_scene(preset: str, std_scale: float, seed: int = 0) -> tuple[np.ndarray, object]:
    """(NUM_FRAMES, H, W) float32 ToF frames of a still room (floor, walls 4.2 m away, a
    cabinet at 1.6 m, a table at 2.6 m), ``std_scale`` times the nominal ToF noise; and the camera."""
    spec = CAMERA_PRESETS[preset]
    camera = camera_preset(preset, world_from_camera=look_at((0.0, 0.0, 1.5), (0.0, 3.0, 0.8)))
    scene = concat([room(width=5.0, depth=4.2, center_xy=(0.0, 2.1)), cabinet((-0.9, 1.6), width=0.8),
                    table((0.8, 2.6))])
    ideal = render_camera(scene, camera).depth
    rng = np.random.default_rng(seed)
    depths = [tof_noise(ideal, rng, min_range=spec.near, max_range=spec.far, std_scale=std_scale)
              for _ in range(NUM_FRAMES)]
    return np.stack(depths), camera


@pytest.mark.parametrize("preset, std_scale", [("kinect_v2", 1.0), ("azure_nfov", 3.0)])
def test_the_estimate_recovers_the_rendered_noise_of_a_still_scene(preset, std_scale):
    depths, _ = _static_scene(preset, std_scale)
    estimate = estimate_depth_noise(depths)
    near, far = estimate.depth_range
    assert near < 1.8 and far > 3.0, estimate.depth_range  # the cabinet, the table, the floor and the walls
    for z in (1.8, 2.5, 3.0):
        truth = std_scale * depth_std(z, "tof")
        assert estimate.std(z) == pytest.approx(truth, rel=0.2), (z, estimate.std(z), truth)
    # the bins themselves, one by one
    np.testing.assert_allclose(estimate.bin_stds, std_scale * depth_std(estimate.bin_depths, "tof"), rtol=0.2)
    assert estimate.frames == NUM_FRAMES and estimate.pixels > 10_000
    # beyond the bins the fitted form goes on: it grows with depth and stays positive
    assert 0 < estimate.std(0.5) and estimate.std(6.0) > estimate.std(far)


def test_a_person_walking_through_does_not_bias_the_estimate():
    """no_occlusion (procedural) on a Kinect v2 with 3 times the nominal noise: the person
    walks 0.9 m across the room in the 20 frames; their pixels are not static and are left
    out, and the estimate stays within 20 % of the rendered noise at every bin."""
    scenario = build_scenario("no_occlusion", use_mocap=False, sensor="kinect_v2")
    model, options = scenario.noise["front"]
    scenario = dataclasses.replace(scenario, noise={"front": (model, {**options, "std_scale": 3.0})})
    rendered = list(frames(scenario, seed=0, num_frames=NUM_FRAMES))
    depths = np.stack([f.depth["front"] for f in rendered])
    person = np.any([f.rendered["front"].person > 0 for f in rendered], axis=0)
    assert person.sum() > 5000  # the person covers many pixels over the frames
    estimate = estimate_depth_noise(depths)
    np.testing.assert_allclose(estimate.bin_stds, 3.0 * depth_std(estimate.bin_depths, "tof"), rtol=0.2)
    for z in np.linspace(*estimate.depth_range, 3):
        assert estimate.std(z) == pytest.approx(3.0 * depth_std(z, "tof"), rel=0.2)
    # without the static cut the walker's pixels would be in: their spread is decimetres
    spread = depths.std(axis=0)
    assert np.median(spread[person & (depths > 0).all(axis=0)]) > 10 * 3.0 * depth_std(3.0, "tof")


def test_too_few_frames_or_pixels_are_refused():
    depths, _ = _static_scene("kinect_v2", 1.0)
    with pytest.raises(ValueError, match="at least 3 frames, got 2"):
        estimate_depth_noise(depths[:2])
    with pytest.raises(ValueError, match="static pixels"):
        estimate_depth_noise(depths[:, :10, :10])  # 100 pixels, fewer than a bin needs
    with pytest.raises(ValueError, match="measured pixels"):
        estimate_depth_noise(np.zeros((5, 8, 8), np.float32))
    with pytest.raises(ValueError, match=r"\(T, H, W\)"):
        estimate_depth_noise(depths[0])


def test_a_preset_matches_a_calibration_a_few_percent_off_and_nothing_else():
    rng = np.random.default_rng(3)
    for name in CAMERA_PRESETS:
        camera = camera_preset(name)
        assert matching_preset(camera) == name
        jitter = {k: getattr(camera, k) * (1 + 0.02 * rng.choice([-1, 1])) for k in ("fx", "fy", "cx", "cy")}
        assert matching_preset(dataclasses.replace(camera, **jitter)) == name  # a real calibration
        assert matching_preset(dataclasses.replace(camera, fx=camera.fx * 1.2)) is None  # 20 % off
        assert matching_preset(dataclasses.replace(camera, fx=camera.fx * 1.02), tolerance=0.01) is None
        binned = dataclasses.replace(camera, width=camera.width // 2, height=camera.height // 2, fx=camera.fx / 2,
                                     fy=camera.fy / 2, cx=camera.cx / 2, cy=camera.cy / 2)
        assert matching_preset(binned) is None  # another resolution
    with pytest.raises(ValueError, match="tolerance must be a share"):
        matching_preset(camera_preset("kinect_v1"), tolerance=-0.1)


def test_each_camera_gets_its_own_noise_and_range():
    azure = dataclasses.replace(camera_preset("azure_nfov", camera_name="a"), fx=504.61 * 1.03)  # calibrated
    odd = dataclasses.replace(camera_preset("kinect_v2", camera_name="b"), width=500)  # no preset
    named = camera_noise([azure, odd], GridConfig(noise_model=None))
    assert (named["a"].model, named["a"].max_range, named["a"].preset) == ("tof", 3.86, "azure_nfov")
    assert (named["b"].model, named["b"].max_range, named["b"].preset) == ("structured_light", 4.5, None)
    assert camera_noise([azure], GridConfig(noise_model=None, max_range=3.0))["a"].max_range == 3.0
    depths, _ = _static_scene("kinect_v2", 2.0)
    estimate = estimate_depth_noise(depths)
    measured = camera_noise([azure, odd], GridConfig(noise_model="measured"), {"a": estimate, "b": estimate})
    assert measured["a"].model is estimate and measured["a"].max_range == 3.86  # the preset's range
    assert measured["b"].max_range == pytest.approx(estimate.far)  # no preset: the farthest it measured
    assert 4.35 < estimate.far <= 4.5  # the back wall's upper corners, 4.46 m along the optical axis
    # a camera without an estimate has its named model, and says why
    some = camera_noise([azure, odd], GridConfig(noise_model="measured"), {"a": estimate, "b": "too few frames"})
    assert some["a"].model is estimate and (some["b"].model, some["b"].max_range) == ("structured_light", 4.5)
    assert some["b"].to_dict()["unmeasured"] == "too few frames" and "unmeasured" not in named["b"].to_dict()
    assert camera_noise([azure], GridConfig(noise_model="measured"))["a"].unmeasured == "not measured"


def test_measure_noise_names_the_camera_it_cannot_measure():
    depths, camera = _static_scene("kinect_v2", 1.0)
    first = [{camera.name: d} for d in depths]
    estimates = measure_noise([camera], first, GridConfig(noise_frames=5))
    assert estimates[camera.name].frames == 5 and isinstance(estimates[camera.name], NoiseEstimate)
    with pytest.raises(ValueError, match="camera 'cam0': .*at least 3 frames, got 2"):
        measure_noise([camera], first[:2])
    reason = measure_noise([camera], first[:2], strict=False)[camera.name]  # what a run records instead
    assert isinstance(reason, str) and "at least 3 frames, got 2" in reason


def test_the_measured_path_records_each_cameras_noise_in_the_summary(tmp_path):
    from occupose.run import track_recording, write_run
    from occupose.synth.generate import write_scenario

    scenario = build_scenario("no_occlusion", use_mocap=False, sensor="kinect_v2")
    write_scenario(scenario, tmp_path / "rec", seed=0, num_frames=6)
    config = TrackerConfig().with_values({"grid.noise_model": "measured", "grid.noise_frames": 5})
    result = track_recording(tmp_path / "rec", config)
    write_run(tmp_path / "out", result, tmp_path / "rec")
    noise = json.loads((tmp_path / "out" / "summary.json").read_text())["noise"]["front"]
    assert noise["model"] == "measured" and noise["frames"] == 5 and noise["pixels"] > 10_000
    assert noise["preset"] == "kinect_v2" and noise["max_range"] == 4.5
    near, far = noise["depth_range"]
    z = 0.5 * (near + far)
    # the recording's depth is whole millimetres: the estimate carries that too
    assert np.polyval(noise["coefficients"][::-1], z) == pytest.approx(depth_std(z, "tof"), rel=0.2)
    named = track_recording(tmp_path / "rec", TrackerConfig().with_values({"grid.noise_model": None}))
    assert named.noise["front"] == {"model": "tof", "coefficients": [1.5e-3, -0.5e-3, 0.3e-3], "max_range": 4.5,
                                    "preset": "kinect_v2"}


def test_a_depth_bin_mostly_crossed_by_a_mover_is_left_out():
    """70 % of the pixels of the 2.5-2.75 m bin are crossed by something in half the frames
    (up to 30 cm nearer): the bin's median spread is the mover's, its static cut lets the
    mover in, and the bin reads far above the others' fit; it is dropped."""
    depths, _ = _static_scene("kinect_v2", 2.0)
    mean = depths.mean(axis=0)
    rng = np.random.default_rng(1)
    crossed = (mean >= 2.5) & (mean < 2.75) & (rng.random(mean.shape) < 0.7) & (depths > 0).all(axis=0)
    assert crossed.sum() > 1000
    moved = depths.copy()
    for t in range(0, NUM_FRAMES, 2):
        moved[t][crossed] -= 0.3 * rng.random(int(crossed.sum())).astype(np.float32)
    estimate = estimate_depth_noise(moved)
    assert not np.any((estimate.bin_depths >= 2.5) & (estimate.bin_depths < 2.75)), estimate.bin_depths
    for z in (1.8, 2.6, 3.0):
        assert estimate.std(z) == pytest.approx(2.0 * depth_std(z, "tof"), rel=0.2)


def test_a_tracker_given_no_measurement_measures_the_noise_on_its_first_frames():
    """grid.noise_model measured, no ``noise=``: the named model for the first
    grid.noise_frames frames, then the measured noise, the grid made again and those frames
    replayed through it: its beliefs are then those of a tracker given the same measurement
    from the start (nobody has started yet, so no hold differs), and it tracks on."""
    from occupose.tracker import Tracker

    scenario = build_scenario("no_occlusion", use_mocap=False, sensor="kinect_v2")
    depths = [f.depth for f in frames(scenario, seed=0, num_frames=8)]
    config = TrackerConfig().with_values({"grid.noise_model": "measured", "grid.noise_frames": 4})
    itself = Tracker(scenario.cameras, scenario.fps, config)
    assert itself.noise["front"].model == "tof"  # named, until measured
    given = Tracker(scenario.cameras, scenario.fps, config, noise=measure_noise(scenario.cameras, depths, config.grid))
    for index, frame in enumerate(depths[:4]):
        itself.update(frame)
        given.update(frame)
        assert itself.noise["front"].model == "tof" if index < 3 else isinstance(itself.noise["front"].model,
                                                                                 NoiseEstimate)
    assert itself.noise["front"].to_dict() == given.noise["front"].to_dict()
    np.testing.assert_allclose(itself.grid.probabilities, given.grid.probabilities, atol=1e-6)
    assert not itself.people and not given.people
    for frame in depths[4:]:
        itself.update(frame)


def test_a_big_surface_outweighs_small_bins_and_the_fit_does_not_fall_with_depth():
    """random-6's first frames, as pixel series: a ceiling camera sees the floor at 2.15-2.65 m
    (135 000 pixels, the nominal structured-light noise), a couch's seat at 1.78 m (20 000
    pixels, 2.1 mm: the seat parallel to the image lies between the disparity steps) and the
    top of a still person's head at 0.74-0.8 m (3 000 pixels, 2.2 mm). Fitted with every bin
    weighing the same, the quadratic through them fell to 0.6 mm at 1.2 m, where the person's
    shoulders are (its run went from 13 to 26-42 cm); weighed by their pixels the small bins
    are off the floor's fit and dropped, and what is left does not fall with depth."""
    rng = np.random.default_rng(0)
    parts = [(np.linspace(2.15, 2.65, 135_000), None), (np.full(20_000, 1.78), 0.0021),
             (np.linspace(0.74, 0.80, 3_000), 0.0022)]
    series = []
    for depth, std in parts:
        scale = depth_std(depth, "structured_light") if std is None else np.full(depth.size, std)
        series.append(depth[:, None] + scale[:, None] * rng.standard_normal((depth.size, NUM_FRAMES)))
    pixels = np.concatenate(series)  # (N, T) metres
    depths = pixels.T.reshape(NUM_FRAMES, 1, -1).astype(np.float32)
    estimate = estimate_depth_noise(depths)
    assert estimate.bin_depths.min() > 2.0, estimate.bin_depths  # the couch's and the head's bins left out
    z = np.linspace(0.8, 2.6, 10)
    assert np.all(np.diff(estimate.std(z)) >= 0)
    np.testing.assert_allclose(estimate.std(z), depth_std(z, "structured_light"), rtol=0.35)
