"""Settings and cameras under bad, careless and hostile values (issue 26, the rows of
reviews/bad-inputs-931038f.md about settings, resource bounds, camera poses and the
library's arguments): each is refused before any work with a message naming the setting
and, for a bound, what it would cost; the command exits non-zero, writes no output and
leaves the recording as it was.

One 3-frame recording is rendered for the module (``occupose synth no_occlusion``); the
rows that change the camera edit copies of its ``recording.json``.
"""

import json
import math
import shutil
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from occupose.camera import Camera, look_at
from occupose.cli import main
from occupose.config import ConfigError, TrackerConfig
from occupose.io.recording import Recording
from occupose.run import track_frames, track_recording
from occupose.tracker import Tracker
from occupose.testing import folder_snapshot

FRAMES = 3


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("settings") / "rec"
    result = CliRunner().invoke(main, ["synth", "no_occlusion", str(out), "--frames", str(FRAMES), "--procedural"])
    assert result.exit_code == 0, result.output
    return out


def _camera_changed(recording: Path, folder: Path, change) -> Path:
    """A copy of ``recording`` in ``folder`` whose camera entry went through ``change``."""
    copy = folder / "rec"
    shutil.copytree(recording, copy)
    header = json.loads((copy / "recording.json").read_text())
    change(header)
    (copy / "recording.json").write_text(json.dumps(header))
    return copy


def _set(key, value):
    def change(header):
        header["cameras"][0][key] = value
    return change


def _fps(value):
    def change(header):
        header["fps"] = value
    return change


def _pose(transform):
    def change(header):
        pose = np.asarray(header["cameras"][0]["world_from_camera"])
        header["cameras"][0]["world_from_camera"] = transform(pose).tolist()
    return change


def _flipped(pose):  # turned 180 deg about its own x axis: looking 13 deg up, upside down
    return pose @ np.diag([1.0, -1.0, -1.0, 1.0])


def _moved(offset):
    def transform(pose):
        pose = pose.copy()
        pose[:3, 3] += offset
        return pose
    return transform


def _at_height(z):
    def transform(pose):
        pose = pose.copy()
        pose[2, 3] = z
        return pose
    return transform


def _check_refused(result, message: str, status: int, out: Path, recording: Path, before: dict) -> None:
    assert result.exit_code == status, result.output
    assert message in result.output, result.output
    assert "Traceback" not in result.output
    assert not out.exists()
    assert folder_snapshot(recording) == before


# -------------------------------------------------------------- the recording's camera and frame rate

CAMERA_ROWS = [  # row, change of recording.json, distinctive part of the message
    ("13 fps 1e-300", _fps(1e-300), "fps = 1e-300 frames/s is outside the frame rates tracked, 1 .. 1000"),
    ("14 fps 1e300", _fps(1e300), "fps = 1e+300 frames/s is outside the frame rates tracked"),
    ("15 fps 1e6", _fps(1e6), "fps = 1e+06 frames/s is outside the frame rates tracked"),
    ("30 cx 1e9", _set("cx", 1e9), "put its corner rays 90.0 deg from the optical axis; a pinhole camera's stay "
                                   "within 75 deg (limits.ray_angle_deg)"),
    ("32 fx fy 1e-6", lambda h: (_set("fx", 1e-6)(h), _set("fy", 1e-6)(h)), "fx = 1e-06, fy = 1e-06"),
    ("33 looking up", _pose(_flipped), "sees nothing below z = 0.82 m within its far range of 4.5 m (its optical "
                                       "axis 13 deg above the horizontal)"),
    ("33 moved 1e6 m", _pose(_moved([1e6, 0.0, 0.0])), "is 1e+06 m from the world origin; the bound "
                                                       "limits.distance_m is 1000 m"),
    ("33 below the floor", _pose(_at_height(-0.5)), "is at z = -0.5 m, not above the floor"),
    ("33 depth scale x2", _set("depth_scale", 0.002), "sees nothing within its far range of 4.5 m: of its"),
    ("33 depth scale x1.5", _set("depth_scale", 0.0015), "lies more than 0.1 m below the floor"),
]


@pytest.mark.parametrize("row, change, message", CAMERA_ROWS, ids=[r[0] for r in CAMERA_ROWS])
def test_a_camera_or_frame_rate_beyond_the_bounds_is_refused_before_tracking(recording, tmp_path, row, change,
                                                                              message):
    rec = _camera_changed(recording, tmp_path, change)
    before = folder_snapshot(rec)
    result = CliRunner().invoke(main, ["track", str(rec), "--out", str(tmp_path / "out")])
    _check_refused(result, message, 1, tmp_path / "out", rec, before)


def test_a_depth_scale_off_by_half_puts_most_points_below_the_floor(recording, tmp_path):
    rec = _camera_changed(recording, tmp_path, _set("depth_scale", 0.0015))
    with pytest.raises(ValueError, match=r"camera 'front': (\d+) % of what it sees within 4.5 m") as caught:
        track_recording(rec)
    share = int(caught.value.args[0].split(": ")[1].split(" %")[0])
    assert 50 < share <= 100


# ------------------------------------------------------------------------- command-line settings

OPTION_ROWS = [  # row, options of `occupose track`, distinctive part of the message, exit status
    ("73 particles 1e9", ["--particles", "1000000000"],
     "gives 5,000,000,000 likelihood evaluations per person and frame, 5,000,000 times method ours'; the bound "
     "limits.evaluations is 100,000", 1),
    ("74 particles 3e6", ["--particles", "3000000"], "gives 15,000,000 likelihood evaluations", 1),
    ("77 seven layers", ["--layers", "1,2,3,4,5,6,7"],
     "pose.layers must hold one number per partitioned-sampling stage", 1),
    ("78 layers 100000", ["--layers", "100000"], "filter's 300000 likelihood calls a frame (pose.layers = 100000) "
                                                 "gives 60,000,000", 1),
    ("78 particles x layers", ["--particles", "100000", "--layers", "100"], "gives 30,000,000", 1),
    ("79 seed -1", ["--seed", "-1"], "-1 is not in the range x>=0", 2),
    ("80 method", ["--method", "nonsense"], "unknown method 'nonsense'; valid names: ours, apf, ps, part-based", 1),
    ("81 model", ["--model", "nonsense"], "'nonsense' is not one of 'auto', 'full', 'upper'", 2),
    ("82 filter", ["--filter", "nonsense"], "pose.filter must be one of sir, apf, ps, apf+ps, part-based; got "
                                            "'nonsense'", 1),
    ("82 likelihood", ["--likelihood", "nonsense"], "pose.likelihood must be one of points, free,", 1),
    ("83 filter likelihood layers", ["--filter", "nonsense", "--likelihood", "bogus", "--layers", "0"],
     "pose.filter must be one of", 1),
    ("83 layers 0", ["--layers", "0"], "pose.layers must be >= 1, got 0", 1),
    ("85 layers for sir", ["--filter", "sir", "--layers", "3"], "pose.layers must be none for the 'sir' filter", 1),
    ("--set bool text", ["--set", "occlusion.enabled=False"], "occlusion.enabled must be true or false, got "
                                                              "'False' (str)", 1),
    ("--set float for int", ["--set", "pose.particles=1e3"], "pose.particles must be an integer, got 1000.0", 1),
    ("--set layers text", ["--set", "pose.layers=3,1,1"], "pose.layers must be a list, got '3,1,1' (str)", 1),
    ("--set no value", ["--set", "pose.gate_m"], "--set takes KEY=VALUE", 1),
    ("--set unknown", ["--set", "pose.gate=0.3"], "unknown setting 'pose.gate'; pose has:", 1),
    ("--set cell 0.002", ["--set", "grid.cell=0.002"], "grid.cell = 0.002 m gives a grid of 2424 x 2381 x 1101 = "
                                                       "6.35e+09 cells", 1),
]


@pytest.mark.parametrize("row, options, message, status", OPTION_ROWS, ids=[r[0] for r in OPTION_ROWS])
def test_a_bad_option_is_refused_before_any_work(recording, tmp_path, row, options, message, status):
    before = folder_snapshot(recording)
    result = CliRunner().invoke(main, ["track", str(recording), "--out", str(tmp_path / "out"), *options])
    _check_refused(result, message, status, tmp_path / "out", recording, before)


CONFIG_ROWS = [  # row, config file (TOML), distinctive part of the message
    ("89 particles text", '[pose]\nparticles = "many"\n', "pose.particles must be an integer, got 'many' (str)"),
    ("89 particles 0", "[pose]\nparticles = 0\n", "pose.particles must be >= 1, got 0"),
    ("89 particles -5", "[pose]\nparticles = -5\n", "pose.particles must be >= 1, got -5"),
    ("89 particles 50.7", "[pose]\nparticles = 50.7\n", "pose.particles must be an integer, got 50.7 (float)"),
    ("89 method 5", "method = 5\n", "unknown method 5; valid names: ours, apf, ps, part-based"),
    ("89 cell 0", "[grid]\ncell = 0\n", "grid.cell must be >= 0.001, got 0.0"),
    ("89 cell text", '[grid]\ncell = "5cm"\n', "grid.cell must be a finite number, got '5cm' (str)"),
    ("89 max_gap_s -1", "[blobs]\nmax_gap_s = -1\n", "blobs.max_gap_s must be >= 0, got -1.0"),
    ("89 max_gap_s text", '[blobs]\nmax_gap_s = "x"\n', "blobs.max_gap_s must be a finite number, got 'x' (str)"),
    ("89 max_points 0", "[pose]\nmax_points = 0\n", "pose.max_points must be >= 1, got 0"),
    ("89 model", '[pose]\nmodel = "nonsense"\n', "pose.model must be one of auto, full, upper; got 'nonsense'"),
    ("89 seed", "seed = -1\n", "unknown section 'seed'; valid: method, grid, blobs,"),
    ("90 seed text", 'seed = "abc"\n', "(the seed is no setting: give it with --seed, or seed= in Python)"),
    ("91 old options table", "[grid_options]\nbogus = 1\n", "unknown section 'grid_options'"),
    ("91 a section as a number", "grid = 5\n", "section 'grid' must be a table of settings, got 5 (int)"),
    ("91 unknown setting", "[grid]\nbogus = 1\n", "unknown setting 'grid.bogus'; grid has: cell, height,"),
    ("91 a table in a section", "[pose.options]\nparticles = 10\n", "unknown setting 'pose.options'; pose has:"),
    ("91 a table for a number", "[pose]\nparticles = {value = 10}\n", "pose.particles must be an integer, got "
                                                                      "{'value': 10} (dict)"),
    ("92 look_back_s text", '[start]\nlook_back_s = "x"\n', "start.look_back_s must be a finite number, got 'x'"),
    ("93 layers of text", '[pose]\nlayers = ["a", "b"]\n', "pose.layers[0] must be an integer, got 'a' (str)"),
    ("94 occlusion text", '[occlusion]\nenabled = "false"\n', "occlusion.enabled must be true or false, got "
                                                              "'false' (str)"),
    ("94 shape text", '[shape]\nlearn = "no"\n', "shape.learn must be true or false, got 'no' (str)"),
    ("95 cell 0.002", "[grid]\ncell = 0.002\n", "about 458 GB; the bound limits.grid_cells is 20,000,000 cells"),
    ("96 cell 0.01", "[grid]\ncell = 0.01\n", "grid.cell = 0.01 m gives a grid of 485 x 477 x 221 = 5.11e+07 "
                                              "cells"),
    ("far range 100 m", "[grid]\nmax_range = 100.0\n", "the bound limits.grid_cells is 20,000,000 cells"),
    ("limits crossed", "[limits]\nmin_fps = 100.0\nmax_fps = 10.0\n", "limits.min_fps must be <= limits.max_fps"),
]


@pytest.mark.parametrize("row, toml, message", CONFIG_ROWS, ids=[r[0] for r in CONFIG_ROWS])
def test_a_bad_config_file_is_refused_before_any_work(recording, tmp_path, row, toml, message):
    config = tmp_path / "settings.toml"
    config.write_text(toml)
    before = folder_snapshot(recording)
    result = CliRunner().invoke(main, ["track", str(recording), "--out", str(tmp_path / "out"), "--config",
                                       str(config)])
    _check_refused(result, message, 1, tmp_path / "out", recording, before)
    assert config.read_text() == toml


def test_the_config_command_refuses_what_track_refuses(tmp_path):
    result = CliRunner().invoke(main, ["config", "--set", "pose.particles=1000000"])
    assert result.exit_code == 1 and "gives 5,000,000 likelihood evaluations per person and frame" in result.output


def test_demo_refuses_an_unknown_method_before_rendering(tmp_path):
    result = CliRunner().invoke(main, ["demo", "--out", str(tmp_path / "demo"), "--method", "nonsense",
                                       "--frames", "2"])
    assert result.exit_code == 1 and "unknown method 'nonsense'" in result.output  # row 125
    assert not (tmp_path / "demo").exists()


# --------------------------------------------------------------------------------- the library

@pytest.fixture(scope="module")
def opened(recording):
    return Recording(recording)


LIBRARY_ROWS = [  # row, call on the opened recording, exception, distinctive part of the message
    ("132 None", lambda rec: track_recording(None), TypeError,
     "recording must be a frame source (occupose.io.sources.FrameSource, e.g. a Recording) or the path of a recording, got NoneType"),
    ("132 a number", lambda rec: track_recording(5), TypeError, "got int"),
    ("133 seed text", lambda rec: track_recording(rec, seed="x"), TypeError, "seed must be an integer >= 0, got 'x'"),
    ("133 seed float", lambda rec: track_recording(rec, seed=1.5), TypeError, "got 1.5 (float)"),
    ("133 seed -1", lambda rec: track_recording(rec, seed=-1), ValueError, "seed must be an integer >= 0, got -1"),
    ("133 seed bool", lambda rec: track_recording(rec, seed=True), TypeError, "got True (bool)"),
    ("134 particles text", lambda rec: TrackerConfig.from_dict({"pose": {"particles": "10"}}), ConfigError,
     "pose.particles must be an integer, got '10' (str)"),
    ("134 config dict", lambda rec: track_recording(rec, {"pose": {"particles": 10}}), ConfigError,
     "config must be a TrackerConfig or a method name, got dict (settings as a dict: TrackerConfig.from_dict)"),
    ("134 config method", lambda rec: track_recording(rec, "nonsense"), ConfigError, "unknown method 'nonsense'"),
    ("135 progress", lambda rec: track_recording(rec, progress=5), TypeError,
     "progress must be a function or None, got 5 (int)"),
    ("135 overlap", lambda rec: track_recording(rec, overlap="yes"), TypeError,
     "overlap must be True or False, got 'yes' (str)"),
    ("136 no cameras", lambda rec: Tracker([], 30.0), TypeError, "cameras must be a non-empty sequence"),
    ("136 fps 0", lambda rec: Tracker(rec.cameras, 0), ValueError, "fps must be a positive finite number, got 0"),
    ("136 fps nan", lambda rec: Tracker(rec.cameras, math.nan), ValueError, "got nan"),
    ("136 fps text", lambda rec: Tracker(rec.cameras, "30"), ValueError, "fps must be a number, got '30'"),
    ("136 seed text", lambda rec: Tracker(rec.cameras, 30.0, seed="x"), TypeError, "seed must be an integer"),
    ("136 frames", lambda rec: track_frames(Tracker(rec.cameras, 30.0), rec.frames(), -1), ValueError,
     "num_frames must be an integer >= 0, got -1"),
    ("136 tracker", lambda rec: track_frames("tracker", rec.frames(), 3), TypeError,
     "tracker must be an occupose.tracker.Tracker, got str"),
]


@pytest.mark.parametrize("row, call, error, message", LIBRARY_ROWS, ids=[r[0] for r in LIBRARY_ROWS])
def test_a_bad_argument_of_the_library_is_a_clear_error_naming_it(opened, row, call, error, message):
    with pytest.raises(error) as caught:
        call(opened)
    assert message in str(caught.value)


def test_a_path_is_a_recording(recording):
    result = track_recording(str(recording), seed=0)  # row 132: a path, as a string
    assert result.num_frames == FRAMES and result.seed == 0


def test_an_image_too_large_is_refused_before_anything_is_allocated():
    camera = Camera("wide", 100_000, 100_000, 50_000.0, 50_000.0, 49_999.5, 49_999.5, 0.001,
                    look_at(eye=(0.0, -3.0, 1.6), target=(0.0, 0.0, 1.0)))
    tracemalloc.start()
    with pytest.raises(ValueError, match=r"its 100000 x 100000 image has 10,000,000,000 pixels, 40 GB a depth frame "
                                         r"as float32; the bound limits.image_pixels is 16,777,216"):
        Tracker([camera], 30.0)  # row 31 (the frames' own size is the recording reader's check)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 10_000_000  # bytes: nothing of the image's size was allocated


def test_a_grid_too_large_is_refused_before_anything_is_allocated(opened):
    config = TrackerConfig().with_values({"grid.cell": 0.002})
    tracemalloc.start()
    with pytest.raises(ValueError, match=r"6.35e\+09 cells over the cameras' view \(4.85 x 4.76 x 2.2 m\), about 458 GB"):
        Tracker(opened.cameras, opened.fps, config)  # row 95 (458 GB: 72 bytes a cell)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 10_000_000


def test_a_bound_raised_in_the_config_lets_the_setting_through(small_camera):
    config = TrackerConfig().with_values({"limits.evaluations": 2_000_000, "pose.particles": 400_000})
    assert config.pose.particles == 400_000
    wide = TrackerConfig().with_values({"limits.ray_angle_deg": 80.0, "grid.cell": 0.2})
    squint = Camera("cam", 160, 120, 20.0, 20.0, 79.5, 59.5, 0.001, small_camera.world_from_camera)
    with pytest.raises(ValueError, match="corner rays 78.7 deg"):  # atan(hypot(80, 60) / 20)
        Tracker([squint], 30.0)
    assert Tracker([squint], 30.0, wide).fps == 30.0


def test_a_first_frame_mostly_below_the_floor_is_refused_once_it_has_measurements(small_camera):
    """A first frame that is a wall 3.5 m away crossing the floor (19 % of the small
    camera's points more than 0.1 m below it) passes the default bound, 0.5, not 0.1; a
    frame without measurements leaves the check to the next one."""
    wall = {"cam": np.full((small_camera.height, small_camera.width), 3.5, np.float32)}
    assert Tracker([small_camera], 30.0).update(wall).estimates == {}
    strict = TrackerConfig().with_values({"limits.below_floor_share": 0.1})
    with pytest.raises(ValueError, match=r"camera 'cam': 19 % of what it sees within 4.5 m lies more than 0.1 m "
                                         r"below the floor"):
        Tracker([small_camera], 30.0, strict).update(wall)
    blind = {"cam": np.zeros_like(wall["cam"])}
    tracker = Tracker([small_camera], 30.0, strict)
    tracker.update(blind)  # nothing measured: nothing to check yet
    with pytest.raises(ValueError, match="below the floor"):
        tracker.update(wall)  # the first frame with measurements is checked
