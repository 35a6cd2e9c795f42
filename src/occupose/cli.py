"""The ``occupose`` command line: a thin layer over library calls."""

from __future__ import annotations

import contextlib
import signal
import threading
from pathlib import Path

import click
import numpy as np


def _fail(message: str) -> None:
    raise click.ClickException(message)


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread so that outputs under way are removed."""


def _terminate(signum, frame) -> None:
    raise _Terminated


class _Commands(click.Group):
    """The command group. Ctrl-C (SIGINT) and SIGTERM end a command with one line and exit
    status 130 (143 for SIGTERM), after the output under way is removed: outputs are
    written whole or not at all (occupose.io.output)."""

    def invoke(self, ctx):
        main_thread = threading.current_thread() is threading.main_thread()
        previous = signal.signal(signal.SIGTERM, _terminate) if main_thread else None
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as error:
            what, status = ("terminated", 143) if isinstance(error, _Terminated) else ("interrupted", 130)
            click.echo(f"Error: {what}; no output was left half-written, earlier outputs are as they were", err=True)
            ctx.exit(status)
        finally:
            if main_thread:
                signal.signal(signal.SIGTERM, previous)


def _progress_bar(total: int, desc: str, unit: str = "frame"):
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit=unit, dynamic_ncols=True, mininterval=1.0)


@contextlib.contextmanager
def _progress(desc: str, unit: str = "frame"):
    """A progress callback ``report(n, total)``: its bar opens at the first call, once the
    command has checked its input and outputs and knows the total; closed at the end."""
    bars = []

    def report(n: int, total: int) -> None:
        if not bars:
            bars.append(_progress_bar(total, desc, unit))
        bars[0].update(n)

    try:
        yield report
    finally:
        for bar in bars:
            bar.close()


@click.group(cls=_Commands, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="occupose")
def main() -> None:
    """Track the 3D skeletons of people in depth-camera recordings."""
    from occupose._numba import configure

    configure()


@main.command("scenarios")
def scenarios_cmd() -> None:
    """List the built-in synthetic scenarios."""
    from occupose.synth.scenarios import SCENARIOS

    width = max(map(len, SCENARIOS))
    for name, entry in SCENARIOS.items():
        click.echo(f"{name:<{width}}  {entry.summary}")


def _write_synth(name: str, out: Path, seed: int, frames: int | None, sensor: str | None,
                 force: bool, procedural: bool = False) -> Path:
    from occupose.synth.catalogue import FramesOutOfRange, render_scenario

    try:
        with _progress(f"rendering {name}") as progress:
            made = render_scenario(name, out, seed=seed, frames=frames, sensor=sensor, procedural=procedural,
                                   exists="replace" if force else "refuse", progress=progress)
    except FramesOutOfRange as error:
        _fail(f"--frames must be in 1..{error.available} for {name}, got {frames}")
    except ValueError as error:
        _fail(str(error))
    scenario = made.scenario
    click.echo(f"wrote {out} ({made.num_frames} frames, {len(scenario.cameras)} camera(s), "
               f"{len(scenario.people)} person(s); motion: {scenario.motion_source})")
    return out


#: --force of every command that writes (the rule: README "Commands", occupose.io.output).
_FORCE_HELP = "Replace an earlier output of occupose at the output path (only the files occupose wrote there)."


@main.command("synth")
@click.argument("name")
@click.argument("out", type=click.Path(path_type=Path))
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="Seed of the scene's randomness and sensor noise.")
@click.option("--frames", type=click.IntRange(min=1), default=None, help="Render only the first N frames.")
@click.option("--sensor", default=None, help="Camera model for every camera (kinect_v1, kinect_v2, azure_nfov, realsense_d435).")
@click.option("--procedural", is_flag=True, help="Use the built-in procedural motion even when real mocap clips are present.")
@click.option("--force", is_flag=True, help=_FORCE_HELP)
def synth_cmd(name, out, seed, frames, sensor, procedural, force) -> None:
    """Render the synthetic scenario NAME into the recording folder OUT.

    NAME is a scenario of the catalogue (`occupose scenarios`), "random" (the random scene
    of --seed) or random-<seed>; a random scene's conditions go to OUT/scene.json.
    """
    if name == "random":
        name = f"random-{seed}"
    _write_synth(name, out, seed, frames, sensor, force, procedural)


def _source_options(command):
    """The options of a command that reads a recording of any format (``_open``)."""
    from occupose.io.sources import READERS

    options = [
        click.option("--reader", type=click.Choice(list(READERS)), default=None,
                     help="The recording's format (default: recognised from the path)."),
        click.option("--topic", default=None, help="ROS bags: the depth image topic (default: the only one)."),
        click.option("--tum-camera", default=None, metavar="fr1|fr2|fr3|FILE.json",
                     help="TUM RGB-D folders: the camera's intrinsics, by name or a JSON file of fx, fy, cx, cy "
                          "(default: from freiburg1/2/3 in the folder's name)."),
        click.option("--camera-height", type=click.FloatRange(min=0, min_open=True), default=None,
                     help="A recording without a world pose: the camera's height above the floor, metres "
                          "(with --tilt; default: found from the floor in its first frames)."),
        click.option("--tilt", type=click.FloatRange(-90, 90), default=None,
                     help="... and its optical axis' angle below the horizontal, degrees (90: straight down)."),
        click.option("--world-from-camera", "pose_file", type=click.Path(exists=True, dir_okay=False,
                     path_type=Path), default=None,
                     help="A recording without a world pose: a JSON file of its cameras' poses "
                          "(docs/inputs.md)."),
        click.option("--find-floor", is_flag=True,
                     help="Place the camera from the floor in its frames even when the recording has a pose."),
    ]
    for option in reversed(options):
        command = option(command)
    return command


def _source_kwargs(reader=None, topic=None, tum_camera=None, camera_height=None, tilt=None, pose_file=None,
                   find_floor=False) -> dict:
    """:func:`occupose.io.sources.open_source`'s keyword options from the ``_source_options``."""
    from occupose.io.sources import HeightTilt

    if (camera_height is None) != (tilt is None):
        _fail("--camera-height and --tilt go together")
    if camera_height is not None and pose_file is not None:
        _fail("give the pose with either --camera-height and --tilt or --world-from-camera, not both")
    pose = HeightTilt(camera_height, tilt) if camera_height is not None else pose_file
    options = {} if topic is None else {"topic": topic}
    if tum_camera is not None:
        options["camera"] = tum_camera
    return {"format": reader, "pose": pose, "find_floor": find_floor, **options}


def _open(recording: Path, floor=None, **source):
    """The recording at ``recording`` (any format) with its cameras placed (the
    ``_source_options``); a pose found from the floor or given is printed to stderr."""
    from occupose.io.sources import open_source, placement

    source = open_source(recording, floor=floor, **_source_kwargs(**source))
    for entry in placement(source):
        if entry["pose"] != "recording":
            click.echo(f"{entry['name']}: {entry['height_m']:.3f} m above the floor, tilted {entry['tilt_deg']:.1f} "
                       f"deg down, roll {entry['roll_deg']:.1f} deg ({'found from the floor' if entry['pose'] == 'floor' else 'given'})",
                       err=True)
    return source


@main.command("show")
@click.argument("recording", type=click.Path(exists=True, path_type=Path))
@_source_options
@click.option("--frame", "index", type=click.IntRange(min=0), default=0, show_default=True)
@click.option("--out", type=click.Path(path_type=Path), required=True,
              help="PNG file to write (.png is appended to a name without a suffix).")
@click.option("--tracks", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None,
              help="A tracks.csv to draw beside the ground truth.")
@click.option("--force", is_flag=True, help=_FORCE_HELP)
def show_cmd(recording, index, out, tracks, force, **source) -> None:
    """Write a PNG of one frame of RECORDING (any format, docs/inputs.md): depth
    colour-mapped, skeletons drawn over it."""
    from occupose.viz import show_frame

    try:
        rec = _open(recording, **source)
        track_data = _read_tracks(tracks, rec.num_frames, allow_unmarked=True) if tracks else None
        path = show_frame(rec, index, out, track_data, force=force)
    except (ValueError, FileNotFoundError) as error:
        _fail(str(error))
    click.echo(f"wrote {path}")


@main.command("video")
@click.argument("recording", type=click.Path(exists=True, path_type=Path))
@_source_options
@click.option("--tracks", type=click.Path(exists=True, dir_okay=False, path_type=Path), required=True,
              help="The tracks.csv to draw.")
@click.option("--out", type=click.Path(path_type=Path), required=True,
              help="MP4 file to write (.mp4 is appended to a name without a suffix).")
@click.option("--camera", default=None, help="The camera to show (default: the recording's first).")
@click.option("--fps", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Frames per second of the video (default: the recording's).")
@click.option("--force", is_flag=True, help=_FORCE_HELP)
def video_cmd(recording, tracks, out, camera, fps, force, **source) -> None:
    """Write an MP4 video of RECORDING (any format, docs/inputs.md) seen by one camera:
    every frame's depth colour-mapped, the TRACKS' skeletons drawn over it (docs/outputs.md)."""
    from occupose.viz_video import write_video

    try:
        rec = _open(recording, **source)
        track_data = _read_tracks(tracks, rec.num_frames, allow_unmarked=True)
        with _progress("video") as progress:
            path = write_video(rec, track_data, out, camera=camera, fps=fps, force=force,
                               progress=lambda n: progress(n, rec.num_frames))
    except (ValueError, FileNotFoundError, ImportError) as error:
        _fail(str(error))
    click.echo(f"wrote {path}")


@main.command("view")
@click.argument("recording", type=click.Path(exists=True, path_type=Path))
@_source_options
@click.option("--tracks", type=click.Path(exists=True, dir_okay=False, path_type=Path), required=True,
              help="The tracks.csv to show.")
@click.option("--out", type=click.Path(path_type=Path), required=True,
              help="Rerun recording to write (.rrd is appended to a name without a suffix).")
@click.option("--force", is_flag=True, help=_FORCE_HELP)
def view_cmd(recording, tracks, out, force, **source) -> None:
    """Write a rerun recording (.rrd, open it with `rerun FILE.rrd`) of RECORDING (any
    format, docs/inputs.md): its cameras, depth images and the TRACKS' skeletons in 3D over
    time (docs/outputs.md)."""
    from occupose.viz_rerun import write_rerun

    try:
        rec = _open(recording, **source)
        track_data = _read_tracks(tracks, rec.num_frames, allow_unmarked=True)
        with _progress("rerun recording") as progress:
            path = write_rerun(rec, track_data, out, force=force, progress=lambda n: progress(n, rec.num_frames))
    except (ValueError, FileNotFoundError, ImportError) as error:
        _fail(str(error))
    click.echo(f"wrote {path}")


@main.command("score")
@click.argument("recording", type=click.Path(exists=True, path_type=Path))
@_source_options
@click.argument("tracks", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--unmarked", is_flag=True, help="Score a tracks.csv without the end line occupose writes (one "
              "another program wrote), with a warning: a file cut short at a line boundary looks the same.")
def score_cmd(recording, tracks, unmarked, **source) -> None:
    """Print the Table I row of TRACKS (a tracks.csv) against RECORDING's ground truth."""
    try:
        click.echo(score_text(_open(recording, **source), tracks, allow_unmarked=unmarked))
    except (ValueError, FileNotFoundError) as error:
        _fail(str(error))


def _read_tracks(path: Path, num_frames: int, allow_unmarked: bool = False):
    """read_tracks_csv, its warning (a file without the end line) printed to stderr."""
    import warnings

    from occupose.io.joint_table import UnmarkedTableWarning, read_tracks_csv

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", UnmarkedTableWarning)
        tracks = read_tracks_csv(path, num_frames, allow_unmarked=allow_unmarked)
    for warning in caught:
        click.echo(f"warning: {warning.message}", err=True)
    return tracks


def score_text(rec, tracks_path: Path, allow_unmarked: bool = False) -> str:
    """Table I rows (all joints and ground-truth-visible joints) for each ground-truth person.
    ``allow_unmarked``: read a tracks.csv without its end line (`_read_tracks`)."""
    from occupose.evaluation.matching import score
    from occupose.evaluation.report import TABLE_COLUMNS, markdown_table, table_i_cells
    from occupose.joints import NUM_JOINTS

    try:
        gt = rec.groundtruth()  # a RecordingError for a folder or an unreadable file of that name
    except FileNotFoundError:
        raise ValueError(f"{rec.path}: no groundtruth.csv, nothing to score against") from None
    tracks = _read_tracks(tracks_path, rec.num_frames, allow_unmarked)
    result = score(gt.joints, gt.visible, {k: v[0] for k, v in tracks.items()}, rec.fps)
    rows = []
    notes = []
    for pid, person in zip(gt.person_ids, result.persons):
        track = "none" if person.track is None else f"track {person.track}"
        rows.append([f"person {pid} ({track}) all joints", *table_i_cells(person.all_joints)])
        rows.append([f"person {pid} ({track}) visible joints", *table_i_cells(person.visible_joints)])
        if len(person.per_joint_cm) < NUM_JOINTS:
            notes.append(f"person {pid} ({track}): scored on the {len(person.per_joint_cm)} upper-body joints "
                         "(the track has no hip, knee or ankle)")
    lines = [markdown_table(["person", *TABLE_COLUMNS], rows, text_columns=1), *notes]
    lines.append(f"identity switches: {result.identity_switches}; unmatched tracks: "
                 f"{list(result.unmatched_tracks) or 'none'}")
    return "\n".join(lines)


def _value(text: str):
    """A ``--set`` value: TOML syntax (``0.3``, ``true``, ``[2, 1, 2]``, ``"tof"``), ``none``
    unquoted for none (``"none"`` quoted is the text), else the text."""
    import tomllib

    if text == "none":
        return None
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def build_config(config_file: Path | None, method: str | None, values: dict, assignments: tuple[str, ...] = ()):
    """The run's TrackerConfig: the config file's settings (TOML or JSON: an optional
    ``method``, the base, and sections of settings, see docs/configuration.md) on
    ``--method`` (instead of the file's method), then the flags ``values`` (dotted keys;
    None: not given), then the ``--set KEY=VALUE`` ``assignments``. Returns (config, the
    method name it is based on)."""
    from occupose.config import ConfigError, TrackerConfig, read_settings

    try:
        data = {} if config_file is None else read_settings(config_file)
        name = data["method"] = method or data.get("method", "ours")
        config = TrackerConfig.from_dict(data, source=str(config_file or "the command line"))
        given = {k: v for k, v in values.items() if v is not None}
        if "pose.filter" in given and "pose.layers" not in given:
            given["pose.layers"] = _layers_for(given["pose.filter"], config.pose.layers)
        for assignment in assignments:
            key, sign, text = assignment.partition("=")
            if not sign:
                _fail(f"--set takes KEY=VALUE (e.g. pose.gate_m=0.3), got {assignment!r}")
            given[key.strip()] = _value(text.strip())
        return config.with_values(given), name
    except ConfigError as error:
        _fail(str(error))


def _layers_for(filter_name: str, layers):
    """The layers a filter given by --filter alone takes from the method's ``layers``: none
    for a filter without annealing, the same total in one stage for ``apf``, the method's
    own for ``apf+ps`` (else the ``apf`` and ``ours`` methods' defaults)."""
    from occupose.config import METHODS

    if filter_name == "apf":
        return sum(layers) if isinstance(layers, tuple) else layers or METHODS["apf"].pose.layers
    if filter_name == "apf+ps":
        return layers if layers is not None else METHODS["ours"].pose.layers
    return None


def run_tracking(rec, out: Path, config, method: str | None, seed: int, force: bool, formats=(),
                 frame: str = "world", camera: str | None = None) -> tuple[Path, object]:
    """Track ``rec`` into ``out``/tracks.csv and ``out``/summary.json, and ``out``/tracks.<suffix>
    of each of ``formats`` in ``frame`` (``out`` checked first); returns (tracks path, result)."""
    from occupose.run import track_into

    with _progress(f"tracking ({method or 'custom'})") as progress:
        return track_into(out, rec, config, method=method, seed=seed, force=force,
                          progress=lambda n: progress(n, rec.num_frames), formats=formats, frame=frame,
                          camera=camera, warm_up=lambda message: click.echo(message, err=True))


def _output_formats() -> list[str]:
    from occupose.io.writers import WRITERS

    return list(WRITERS)


#: --frame and --camera of the commands that write JSON, BVH or C3D.
_FRAME_HELP = "Coordinates of the JSON, BVH or C3D output: world (z up, metres from the floor) or camera."
_CAMERA_HELP = "The camera of --frame camera (default: the recording's first)."


def _layers(text: str | None):
    """--layers: an integer or integers separated by commas."""
    if text is None:
        return None
    try:
        parsed = [int(x) for x in text.split(",")]
    except ValueError:
        _fail(f"--layers must be an integer or integers separated by commas, got {text!r}")
    return parsed[0] if len(parsed) == 1 else tuple(parsed)


def _settings_options(command):
    """The options of a command that tracks: its settings (``_config_of``)."""
    options = [
        click.option("--method", default=None, help="ours (default), apf, ps or part-based: the base of the settings."),
        click.option("--model", type=click.Choice(["auto", "full", "upper"]), default=None,
                     help="Body model; auto (default): upper for a ceiling camera, full otherwise."),
        click.option("--filter", "filter_name", default=None, help="Particle filter (sir, apf, ps, apf+ps, part-based)."),
        click.option("--likelihood", default=None, help="Likelihood (points, points+free, render, ...)."),
        click.option("--particles", type=click.IntRange(min=1), default=None, help="Particles per person."),
        click.option("--layers", default=None, help="Annealing layers: an integer or one per stage, e.g. 3,1,1."),
        click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True, help="Random seed."),
        click.option("--config", "config_file", type=click.Path(exists=True, dir_okay=False, path_type=Path),
                     default=None, help="TOML or JSON file of settings (see docs/configuration.md); options given "
                     "here win."),
        click.option("--set", "assignments", multiple=True, metavar="KEY=VALUE",
                     help="Any setting by its dotted name, e.g. --set pose.gate_m=0.3 (repeatable; none for none)."),
    ]
    for option in reversed(options):
        command = option(command)
    return command


def _tracking_options(command):
    """The options of a command that tracks into a run's folder: the settings and the outputs."""
    options = [
        click.option("--format", "output_format", type=click.Choice(["csv", *_output_formats()]), default="csv",
                     show_default=True, help="Another output beside tracks.csv: OUT/tracks.json, .bvh or .c3d "
                     "(docs/outputs.md)."),
        click.option("--frame", type=click.Choice(["world", "camera"]), default="world", show_default=True,
                     help=_FRAME_HELP),
        click.option("--camera", default=None, help=_CAMERA_HELP),
    ]
    for option in reversed(options):
        command = option(command)
    return _settings_options(command)


def _config_of(method, model, filter_name, likelihood, particles, layers, config_file, assignments):
    """The run's config and its base method's name from the ``_tracking_options``."""
    values = {"pose.model": model, "pose.filter": filter_name, "pose.likelihood": likelihood,
              "pose.particles": particles, "pose.layers": _layers(layers)}
    return build_config(config_file, method, values, assignments)


@main.command("track")
@click.argument("recording", type=click.Path(exists=True, path_type=Path))
@_source_options
@click.option("--out", type=click.Path(path_type=Path), required=True, help="Folder for tracks.csv and summary.json.")
@_tracking_options
@click.option("--force", is_flag=True, help=_FORCE_HELP)
def track_cmd(recording, out, method, model, filter_name, likelihood, particles, layers, seed, config_file,
              assignments, output_format, frame, camera, force, **source) -> None:
    """Track everyone in RECORDING (any format, docs/inputs.md): writes OUT/tracks.csv and
    OUT/summary.json (and OUT/tracks.FORMAT with --format) and prints the Table I row when
    the recording has ground truth."""
    config, name = _config_of(method, model, filter_name, likelihood, particles, layers, config_file, assignments)
    try:
        rec = _open(recording, floor=config.floor, **source)
        if rec.num_frames == 0:
            _fail(f"{recording}: the recording has no frames, nothing to track")
        formats = () if output_format == "csv" else (output_format,)
        tracks_path, result = run_tracking(rec, out, config, name, seed, force, formats, frame, camera)
        click.echo(f"{len(result.tracks)} track(s) in {result.num_frames} frames at {result.fps:.1f} frames/s "
                   f"-> {tracks_path}")
        if not result.tracks:
            click.echo("nobody was tracked (no moving person-sized blob in the recording)"
                       + (f": no tracks.{output_format} written" if output_format != "csv" else ""))
        if rec.has_groundtruth:
            click.echo(score_text(rec, tracks_path))
    except (ValueError, FileNotFoundError, ImportError) as error:
        _fail(str(error))


@main.command("fit")
@click.argument("images", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option("--camera", "camera_option", required=True, metavar="PRESET|FILE.json",
              help="The camera: a preset (kinect_v1, kinect_v2, azure_nfov, realsense_d435) or a JSON file of width, "
              "height, fx, fy, cx, cy and optionally world_from_camera (docs/outputs.md, single frames).")
@click.option("--out", type=click.Path(path_type=Path), required=True,
              help="Folder for tracks.csv, summary.json and a picture per image.")
@click.option("--model", type=click.Choice(["auto", "full", "upper"]), default="auto", show_default=True,
              help="Body model; auto: the full body when the legs are in view above a floor, else the upper body.")
@click.option("--depth-scale", type=click.FloatRange(min=0, min_open=True), default=None,
              help="Metres per unit of the images (default: the camera's, 0.001 for a preset; metres for a float .npy).")
@click.option("--background", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None,
              help="An image of the empty scene from the same camera (default: every measured pixel is a person's "
              "or the floor's, as in an image whose background was removed).")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True, help="Random seed.")
@click.option("--config", "config_file", type=click.Path(exists=True, dir_okay=False, path_type=Path),
              default=None, help="TOML or JSON file of settings (docs/configuration.md: fit, start, pose, size).")
@click.option("--set", "assignments", multiple=True, metavar="KEY=VALUE",
              help="Any setting by its dotted name, e.g. --set fit.steps=20 (repeatable).")
@click.option("--force", is_flag=True, help=_FORCE_HELP)
def fit_cmd(images, camera_option, out, model, depth_scale, background, seed, config_file, assignments,
            force) -> None:
    """Fit the body to each of the single depth IMAGES (16-bit PNG, .npy, or raw uint16 of the
    camera's size) with no motion and no background model: OUT/tracks.csv (frame i = the
    i-th image, a track per person and image), OUT/<image name>.png and OUT/summary.json.
    Coordinates are the camera's (x right, y down, z forward, metres) unless the camera
    file gives world_from_camera."""
    from occupose.fit_run import fit_into
    from occupose.io.depth_image import camera_from_option

    config, _ = build_config(config_file, None, {}, assignments)
    try:
        camera, world = camera_from_option(camera_option)
        with _progress("fitting", unit="image") as progress:
            progress(0, len(images))
            summary = fit_into(out, list(images), camera, world=world, model=model, background=background,
                               depth_scale=depth_scale, config=config, seed=seed, force=force,
                               progress=lambda n: progress(n, len(images)))
    except (ValueError, FileNotFoundError) as error:
        _fail(str(error))
    seconds = sum(frame["seconds"] for frame in summary["frames"])
    click.echo(f"{summary['people']} person(s) in {summary['images']} image(s), {seconds / summary['images']:.2f} s "
               f"per image, coordinates in the {summary['frame']} frame -> {out / 'tracks.csv'}")
    if not summary["people"]:
        click.echo(f"nobody was found: no group of at least {config.fit.min_points} points and {config.fit.min_height} m "
                   f"tall{'' if background else ' (without --background every measured pixel counts)'}")


@main.command("batch")
@click.argument("inputs", nargs=-1, required=True, type=click.Path(exists=True, path_type=Path))
@_source_options
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Folder of the batch: OUT/<recording name>/ per recording and OUT/batch.csv.")
@click.option("--jobs", type=click.IntRange(min=1), default=1, show_default=True,
              help="Recordings tracked at once, each in a worker process with one numba thread (1: in this process).")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Track on an existing Dask distributed cluster, e.g. tcp://host:8786 (extra dask), not locally.")
@_tracking_options
@click.option("--force", is_flag=True, help="Track again the recordings done earlier (otherwise skipped), replacing "
              "only what occupose wrote.")
def batch_cmd(inputs, out, jobs, scheduler, method, model, filter_name, likelihood, particles, layers, seed,
              config_file, assignments, output_format, frame, camera, force, **source) -> None:
    """Track every recording of INPUTS (any formats, the same options for all) into
    OUT/<name>/, as `occupose track` would. Recordings done earlier are skipped; one that
    fails is reported and the others go on. Prints a table at the end and writes it as
    OUT/batch.csv; the exit status is 1 when any recording failed."""
    from occupose.batch import TABLE, plan, summary_counts, table_text, track_batch, write_table

    if scheduler is not None and jobs != 1:
        _fail("--jobs is for this machine; a Dask cluster's workers are its own (give --jobs or --scheduler)")
    config, name = _config_of(method, model, filter_name, likelihood, particles, layers, config_file, assignments)
    try:
        tasks = plan(inputs, out, config.to_dict(), method=name, seed=seed, source=_source_kwargs(**source),
                     formats=() if output_format == "csv" else (output_format,), frame=frame, camera=camera,
                     force=force)
        with _progress("batch", unit="recording") as progress:
            progress(0, len(tasks))
            outcomes = track_batch(tasks, jobs=jobs, scheduler=scheduler, progress=lambda outcome: progress(1, len(tasks)))
        table = write_table(out / TABLE, outcomes)
    except (ValueError, ImportError, OSError) as error:
        _fail(str(error))
    click.echo(table_text(outcomes))
    counts = summary_counts(outcomes)
    click.echo(f"{counts['done']} done, {counts['skipped']} skipped (done earlier), {counts['failed']} failed -> {table}")
    if counts["failed"]:
        click.get_current_context().exit(1)


@main.command("live")
@click.option("--realsense", is_flag=True, required=True,
              help="An Intel RealSense camera (extra realsense), the only kind of live camera so far.")
@click.option("--device", "serial", default=None, metavar="SERIAL", help="The camera's serial number (default: the first).")
@click.option("--bag", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None,
              help="Play a RealSense .bag in real time as if it were the camera.")
@click.option("--every-frame", is_flag=True,
              help="With --bag: play every frame at the tracker's pace instead of in real time (none dropped).")
@click.option("--out", type=click.Path(dir_okay=False, allow_dash=True, path_type=Path), default=Path("-"),
              show_default=True, help="File of the JSON lines, one per tracked frame (-: standard output).")
@click.option("--frames", "max_frames", type=click.IntRange(min=1), default=None,
              help="Stop after N tracked frames (default: until the camera or bag ends, or Ctrl-C).")
@click.option("--camera-height", type=click.FloatRange(min=0, min_open=True), default=None,
              help="The camera's height above the floor, metres (with --tilt; default: found from the floor).")
@click.option("--tilt", type=click.FloatRange(-90, 90), default=None,
              help="... and its optical axis' angle below the horizontal, degrees (90: straight down).")
@click.option("--world-from-camera", "pose_file", type=click.Path(exists=True, dir_okay=False, path_type=Path),
              default=None, help="A JSON file of the camera's pose (docs/inputs.md).")
@_settings_options
@click.option("--force", is_flag=True, help="Replace a JSON lines file occupose wrote at --out.")
def live_cmd(realsense, serial, bag, every_frame, out, max_frames, camera_height, tilt, pose_file, method, model,
             filter_name, likelihood, particles, layers, seed, config_file, assignments, force) -> None:
    """Track people as a RealSense camera delivers its frames, the newest each time: frames
    the tracking has no time for are dropped and counted. One JSON line per tracked frame
    (docs/outputs.md) to --out; a status line (frames, drops, latency) on stderr every second."""
    from occupose.live import RealSenseCamera, track_live

    config, _ = _config_of(method, model, filter_name, likelihood, particles, layers, config_file, assignments)
    pose = _source_kwargs(camera_height=camera_height, tilt=tilt, pose_file=pose_file)["pose"]
    try:
        if every_frame and bag is None:
            raise ValueError("--every-frame plays a --bag: a camera's frames come in real time")
        with RealSenseCamera(serial=serial, bag=bag, real_time=not every_frame) as camera, \
                _json_lines(out, force) as stream:
            summary = track_live(camera, config, out=stream, pose=pose, seed=seed, max_frames=max_frames,
                                 status=lambda line: click.echo(line, err=True))
    except (ValueError, FileNotFoundError, ImportError) as error:
        _fail(str(error))
    click.echo(f"camera placed from {'the floor' if summary.pose == 'floor' else 'the pose given'}; "
               f"{summary.status()}", err=True)


@contextlib.contextmanager
def _json_lines(out: Path, force: bool):
    """The stream of ``live``'s JSON lines: standard output for ``-``, else the file, written
    as it goes (a live run has no end to wait for) and refused if it exists, unless ``force``
    and occupose wrote it (its first line is one of occupose's records)."""
    if str(out) == "-":
        yield click.get_text_stream("stdout")
        return
    if out.exists() and not (force and _is_live_output(out)):
        _fail(f"{out} exists" + (" and was not written by occupose live" if force else " (use --force to replace "
                                                                              "a file occupose live wrote)"))
    with open(out, "w", encoding="utf-8") as stream:
        yield stream


def _is_live_output(path: Path) -> bool:
    import json

    try:
        with open(path, encoding="utf-8") as stream:
            first = stream.readline()
        return not first or {"frame", "device_frame", "people"} <= set(json.loads(first))
    except (OSError, ValueError, TypeError):
        return False


@main.command("convert")
@click.argument("recording", type=click.Path(exists=True, path_type=Path))
@click.argument("out", type=click.Path(path_type=Path))
@_source_options
@click.option("--no-color", is_flag=True, help="Leave the colour images out.")
@click.option("--force", is_flag=True, help="Replace a recording occupose wrote at OUT (only the files it wrote).")
def convert_cmd(recording, out, no_color, force, **source) -> None:
    """Write RECORDING (any format, docs/inputs.md) as occupose's recording folder OUT,
    its cameras placed (the pose found from the floor is written into recording.json)."""
    from occupose.io.convert import convert
    from occupose.io.sources import reader_for

    try:
        rec = _open(recording, **source)
        with _progress("converting") as progress:
            convert(rec, out, reader=reader_for(recording, source["reader"]).name, color=not no_color, force=force,
                    progress=lambda n: progress(n, rec.num_frames))
    except (ValueError, FileNotFoundError, ImportError) as error:
        _fail(str(error))
    click.echo(f"wrote {out} ({rec.num_frames} frames, cameras {', '.join(c.name for c in rec.cameras)})")


@main.command("export")
@click.argument("tracks", type=click.Path(path_type=Path))
@click.option("--to", "to", type=click.Choice(_output_formats()), required=True, help="The format to write.")
@click.option("--out", type=click.Path(path_type=Path), required=True, help="The file to write.")
@click.option("--frame", type=click.Choice(["world", "camera"]), default="world", show_default=True,
              help=_FRAME_HELP)
@click.option("--camera", default=None, help=_CAMERA_HELP)
@click.option("--recording", type=click.Path(path_type=Path), default=None,
              help="The recording the tracks are of (default: the one summary.json beside TRACKS names).")
@click.option("--force", is_flag=True, help="Replace a file of that format that occupose wrote at OUT.")
def export_cmd(tracks, to, out, frame, camera, recording, force) -> None:
    """Write a run's TRACKS (its tracks.csv) as JSON, BVH or C3D (docs/outputs.md)."""
    from occupose.io.export import export_tracks

    try:
        path = export_tracks(tracks, to, out, frame=frame, camera=camera, recording=recording, force=force)
    except (ValueError, FileNotFoundError, ImportError) as error:
        _fail(str(error))
    click.echo(f"wrote {path}")


@main.command("config")
@click.option("--method", default=None, help="ours (default), apf, ps or part-based.")
@click.option("--config", "config_file", type=click.Path(exists=True, dir_okay=False, path_type=Path), default=None,
              help="TOML or JSON file of settings.")
@click.option("--set", "assignments", multiple=True, metavar="KEY=VALUE", help="Any setting by its dotted name.")
def config_cmd(method, config_file, assignments) -> None:
    """Print every setting of a run as TOML, a file that --config reads back. TOML has no
    none: settings that are none are written as comments (the method's value stands)."""
    import tomli_w

    config, name = build_config(config_file, method, {}, assignments)
    lines = [f"# occupose settings: method {name} with the changes given", tomli_w.dumps({"method": name}).rstrip()]
    for section, fields in config.to_dict().items():
        lines.append(f"\n[{section}]")
        for key, value in fields.items():
            lines.append(f"# {key} = none" if value is None else tomli_w.dumps({key: value}).rstrip())
    click.echo("\n".join(lines))


@main.command("demo")
@click.option("--out", type=click.Path(path_type=Path), default=Path("demo-output"), show_default=True)
@click.option("--scenario", default="sit_behind_table", show_default=True)
@click.option("--frames", type=click.IntRange(min=2), default=300, show_default=True)
@click.option("--method", default="ours", show_default=True)
@click.option("--force", is_flag=True, help="Replace an earlier demo's outputs in OUT (only the files occupose wrote).")
def demo_cmd(out, scenario, frames, method, force) -> None:
    """Render a built-in scenario with procedural motion (no shared data needed), track it,
    print the Table I row and picture a frame with the skeletons: OUT/SCENARIO (the
    recording), OUT/SCENARIO-METHOD (the run) and OUT/SCENARIO_frameNNNN.png."""
    from occupose.io.joint_table import read_tracks_csv
    from occupose.io.output import check_output
    from occupose.io.recording import Recording
    from occupose.viz import show_frame

    config, name = build_config(None, method, {})  # before any rendering
    run_out = out / f"{scenario}-{method}"
    try:  # both folders, before any work
        check_output(out / scenario, "recording", force=force)
        check_output(run_out, "run", force=force)
    except ValueError as error:
        _fail(str(error))
    rec_path = _write_synth(scenario, out / scenario, seed=0, frames=frames, sensor=None, force=force,
                            procedural=True)
    rec = Recording(rec_path)
    gt = rec.groundtruth()
    if not np.isfinite(gt.joints[..., 0]).any():
        click.echo(f"nobody is in view in the first {frames} frames: render more with --frames")
        return
    hidden = 100.0 * (1 - gt.visible[np.isfinite(gt.joints[..., 0])].mean())
    click.echo(f"ground truth: {len(gt.person_ids)} person(s), {hidden:.1f} % of their joint observations hidden "
               "(furniture, other people, their own body, image border)")
    try:
        tracks_path, result = run_tracking(rec, run_out, config, name, 0, force)
        click.echo(f"{len(result.tracks)} track(s) at {result.fps:.1f} frames/s (start-up excluded) -> {tracks_path}")
        click.echo(score_text(rec, tracks_path))
        tracks = read_tracks_csv(tracks_path, rec.num_frames)
        present = np.flatnonzero(np.isfinite(gt.joints[..., 0, 0]).any(axis=1))
        if present.size:
            index = int(present[(2 * len(present)) // 3])
            picture = show_frame(rec, index, out / f"{scenario}_frame{index:04d}.png", tracks, force=force)
            click.echo(f"picture: {picture}")
    except (ValueError, FileNotFoundError) as error:
        _fail(str(error))


@main.command("evaluate")
@click.option("--scenarios", default=None, help="Scenarios, comma-separated: catalogue names (see `occupose scenarios`) "
              "or random-<seed> (default: the whole catalogue).")
@click.option("--suite", default=None, help="A whole suite instead of --scenarios: catalogue, or random:N "
              "(the random scenes of seeds 0..N-1).")
@click.option("--methods", default="ours,apf,ps", show_default=True, help="Methods, comma-separated (ours, apf, ps, part-based).")
@click.option("--runs", type=click.IntRange(min=1), default=3, show_default=True, help="Runs per method and scenario (seeds 0..runs-1).")
@click.option("--frames", type=click.IntRange(min=1), default=None, help="At most N frames of each scenario.")
@click.option("--procedural", is_flag=True, help="Use the built-in procedural motion even when real mocap clips are present.")
@click.option("--jobs", type=click.IntRange(min=1), default=None, help="Worker processes (default: one per core; 1: no workers).")
@click.option("--out", type=click.Path(file_okay=False, path_type=Path), required=True,
              help="Folder for recordings/, runs/, results.csv, report.md and the plots.")
@click.option("--force", is_flag=True, help="Replace an earlier evaluation in OUT (its recordings are reused where "
              "the settings match; only the files occupose wrote are replaced).")
def evaluate_cmd(scenarios, suite, methods, runs, frames, procedural, jobs, out, force) -> None:
    """Run methods x scenarios x runs and write OUT/report.md (Table I), OUT/results.csv and plots."""
    from occupose.evaluation.evaluate import evaluate, suite_scenarios
    from occupose.evaluation.report import table_i_markdown, table_rows

    if suite is not None and scenarios is not None:
        _fail("give --scenarios or --suite, not both")
    try:
        if suite is not None:
            scenarios = suite_scenarios(suite)
        with _progress("evaluating") as progress:
            result = evaluate(scenarios, methods, runs, out=out, frames=frames, procedural=procedural,
                              jobs=jobs, progress=progress, force=force)
    except (ValueError, FileNotFoundError) as error:
        _fail(str(error))
    click.echo(table_i_markdown(table_rows(result.runs)))
    click.echo(f"report: {result.report}\nresults: {result.results}\nplots: {len(result.plots)} in {out}")
