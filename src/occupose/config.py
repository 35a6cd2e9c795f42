"""The configuration tree: every setting that shapes a tracking result, in one place.

A :class:`TrackerConfig` is a tree of frozen dataclasses, one section per stage or
policy; every field has a default (the value the results in ``docs/results.md`` were
measured with), a unit and a one-line meaning, and is type-checked when the config is
built (a string ``"false"`` where a bool belongs is an error, not a true value)::

    config = TrackerConfig.from_dict({"method": "apf", "pose": {"particles": 300}})
    config = TrackerConfig.from_file("settings.toml")        # TOML or JSON, same keys
    config = config.with_values({"pose.gate_m": 0.3})        # dotted keys
    config.to_dict()                                          # plain data, for summary.json

The methods of the papers are named configs (:data:`METHODS`, :func:`method_config`):
``ours`` (the default), ``apf``, ``ps`` and ``part-based``. ``docs/configuration.md`` lists
every field; the reasons behind the defaults are in ``docs/notes/``.

Names of registered strategies (filters, likelihoods, resampling schemes, noise models)
are listed here as plain tuples so that building a config imports nothing heavy; a test
checks them against the registries.
"""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib
import types
import typing
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

FILTER_NAMES = ("sir", "apf", "ps", "apf+ps", "part-based")
LIKELIHOOD_NAMES = ("points", "free", "render", "color", "points+free", "points+color", "points+free+color",
                    "render+color")
RESAMPLING_NAMES = ("multinomial", "systematic", "stratified", "residual")
NOISE_MODEL_NAMES = ("none", "structured_light", "tof")
MODEL_NAMES = ("auto", "full", "upper")
FALLBACK_NAMES = ("horizontal", "euclidean")
PART_WEIGHT_NAMES = ("chain", "own")


def setting(default: Any, doc: str, unit: str = "", *, low: float | None = None, high: float | None = None,
            above: float | None = None, choices: tuple[str, ...] | None = None) -> Any:
    """A config field: its default, a one-line meaning, its unit, and the checks of its
    values (``low <= value <= high``, ``value > above``, ``value in choices``; for a tuple,
    of each element)."""
    return field(default=default, metadata={"doc": doc, "unit": unit, "low": low, "high": high, "above": above,
                                            "choices": choices})


class ConfigError(ValueError):
    """A setting of the wrong type or out of its range; the message names the setting."""


def _describe(value: Any) -> str:
    return f"{value!r} ({type(value).__name__})"


def _check_scalar(value: Any, kind: type, name: str) -> Any:
    if kind is bool:
        if not isinstance(value, bool):
            raise ConfigError(f"{name} must be true or false, got {_describe(value)}")
        return value
    if kind is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{name} must be an integer, got {_describe(value)}")
        return value
    if kind is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ConfigError(f"{name} must be a finite number, got {_describe(value)}")
        return float(value)
    if kind is str:
        if not isinstance(value, str):
            raise ConfigError(f"{name} must be a string, got {_describe(value)}")
        return value
    raise TypeError(f"unsupported setting type {kind!r} for {name}")  # a bug in this module


def _check_value(value: Any, hint: Any, name: str) -> Any:
    """``value`` converted to the annotation ``hint`` (int -> float, list -> tuple), or ConfigError."""
    options = typing.get_args(hint) if isinstance(hint, types.UnionType) else (hint,)
    if value is None:
        if type(None) in options:
            return None
        raise ConfigError(f"{name} must be set (it cannot be none), got None")
    errors = []
    for option in (o for o in options if o is not type(None)):
        try:
            if typing.get_origin(option) is tuple:
                args = typing.get_args(option)
                if isinstance(value, (str, bytes)) or not isinstance(value, (list, tuple)):
                    raise ConfigError(f"{name} must be a list, got {_describe(value)}")
                if len(args) == 2 and args[1] is Ellipsis:
                    if not value:
                        raise ConfigError(f"{name} must be a non-empty list")
                    return tuple(_check_scalar(v, args[0], f"{name}[{i}]") for i, v in enumerate(value))
                if len(value) != len(args):
                    raise ConfigError(f"{name} must be a list of {len(args)} values, got {len(value)}")
                return tuple(_check_scalar(v, a, f"{name}[{i}]") for i, (v, a) in enumerate(zip(value, args)))
            return _check_scalar(value, option, name)
        except ConfigError as error:
            errors.append(str(error))
    raise ConfigError(errors[0] if len(errors) == 1 else f"{name}: none of its types fits: " + "; ".join(errors))


def _check_range(value: Any, meta: Mapping[str, Any], name: str) -> None:
    values = value if isinstance(value, tuple) else (value,)
    for v in values:
        if isinstance(v, str):
            if meta["choices"] is not None and v not in meta["choices"]:
                raise ConfigError(f"{name} must be one of {', '.join(meta['choices'])}; got {v!r}")
            continue
        if meta["low"] is not None and v < meta["low"]:
            raise ConfigError(f"{name} must be >= {meta['low']:g}, got {v!r}")
        if meta["high"] is not None and v > meta["high"]:
            raise ConfigError(f"{name} must be <= {meta['high']:g}, got {v!r}")
        if meta["above"] is not None and not v > meta["above"]:
            raise ConfigError(f"{name} must be > {meta['above']:g}, got {v!r}")


class _Section:
    """Checks every field of a frozen dataclass section against its annotation and range."""

    _path = ""

    def __post_init__(self) -> None:
        hints = typing.get_type_hints(type(self))
        for f in dataclasses.fields(self):
            name = f"{self._path}.{f.name}" if self._path else f.name
            value = getattr(self, f.name)
            if dataclasses.is_dataclass(hints[f.name]):
                if not isinstance(value, hints[f.name]):
                    raise ConfigError(f"{name} must be a {hints[f.name].__name__}, got {_describe(value)}")
                continue
            value = _check_value(value, hints[f.name], name)
            if value is not None:
                _check_range(value, f.metadata, name)
            object.__setattr__(self, f.name, value)
        self._check()

    def _check(self) -> None:
        """Checks across fields (subclasses)."""


@dataclass(frozen=True)
class GridConfig(_Section):
    """Stage 1: the occupancy grid and its per-cell HMM (``occupose.grid.occupancy``)."""

    _path = "grid"
    cell: float = setting(0.05, "edge of a grid cell (the grid's size is bounded by limits.grid_cells)", "m",
                          low=0.001, high=0.5)
    height: float = setting(2.2, "top of the grid above the floor (the floor z = 0 is its bottom)", "m", above=0.0)
    max_range: float | None = setting(None, "how far along its optical axis each camera's view is kept; none: "
                                            "the camera's sensor preset's far range (for a camera that matches "
                                            "no preset: the farthest depth it measured with grid.noise_model "
                                            "measured, else 4.5 m)", "m", above=0.0)
    noise_model: str | None = setting("measured", "depth noise model of every camera; none (or preset): the "
                                                  "camera's sensor preset's (structured_light for a camera that "
                                                  "matches no preset); measured: each camera's own, from the "
                                                  "temporal spread of its static pixels in the first "
                                                  "grid.noise_frames frames (the preset's where they allow no "
                                                  "estimate, and until they are measured)",
                                      choices=NOISE_MODEL_NAMES + ("measured", "preset"))
    noise_frames: int = setting(30, "grid.noise_model measured: frames at the start of a recording whose static "
                                    "pixels give each camera's depth noise", "frames", low=3, high=1000)
    noise_bin: float = setting(0.25, "grid.noise_model measured: width of the depth bins the noise is measured "
                                     "in", "m", low=0.05, high=2.0)
    noise_static_cut: float = setting(3.0, "grid.noise_model measured: a pixel is static when its temporal std is "
                                           "at most its depth bin's median plus this many robust spreads (MAD "
                                           "x 1.4826) of the bin's pixels", "spreads", above=0)
    noise_min_pixels: int = setting(200, "grid.noise_model measured: fewest static pixels of a depth bin that is "
                                         "used", "pixels", low=10)
    preset_tolerance: float = setting(0.05, "a camera is taken for a sensor preset (its noise model and far "
                                            "range) when its image size is the preset's and its fx, fy, cx, cy "
                                            "are within this share of the preset's", "share", low=0, high=0.5)
    alpha: float = setting(0.01, "HMM transition O -> E: a static object is removed", "probability", low=0, high=1)
    beta: float = setting(0.1, "HMM transition E -> M: something enters a free cell", "probability", low=0, high=1)
    gamma: float = setting(0.4, "HMM transition M -> E: a moving object leaves", "probability", low=0, high=1)
    psi: float = setting(math.exp(-38.0), "HMM transition M -> O: a moving object settles (77 frames to "
                                          "background at the defaults)", "probability", low=0, high=1)
    p_occ: float = setting(0.9, "observation function where the measured surface is in the cell", "probability",
                           above=0.5, high=1)
    p_free: float = setting(0.05, "observation function where the cell is seen through", "probability",
                            low=0, high=0.5)
    tail_width: float = setting(2.0, "width of the observation function's tails", "sensor depth std", low=0)
    initial: tuple[float, float, float] = setting((0.4, 0.0, 0.6), "initial distribution over (O, M, E)",
                                                  "probability", low=0, high=1)
    no_return: float = setting(0.5, "factor on a static object's likelihood in a cell in front of a pixel that "
                                    "measured nothing, nearer than the camera's far range (1: no evidence, "
                                    "the paper's model)", "likelihood ratio", above=0, high=1)
    no_return_after: int = setting(15, "frames in a row a pixel must have measured nothing before it counts as no "
                                      "return for no_return (a background beyond range returns nothing in every "
                                      "frame; a dropout on a surface lasts a frame or a few)", "frames", low=1)
    hold_people: bool = setting(True, "hold the cells of the people estimated in the last frame as moving, so a "
                                      "person standing still is not absorbed into the background")
    hold_margin: float = setting(0.1, "margin around each body capsule of the held cells", "m", low=0)

    def _check(self) -> None:
        if abs(sum(self.initial) - 1.0) > 1e-6:
            raise ConfigError(f"grid.initial must sum to 1, got {list(self.initial)}")
        if self.gamma + self.psi > 1.0:
            raise ConfigError(f"grid.gamma + grid.psi must be <= 1, got {self.gamma} + {self.psi}")


@dataclass(frozen=True)
class BlobConfig(_Section):
    """Stage 2: moving cells labelled into person-like blobs and tracked (``occupose.grid.blobs``,
    ``occupose.grid.tracking``)."""

    _path = "blobs"
    min_cells: int = setting(40, "fewest cells of a kept blob", "cells", low=1)
    min_height: float = setting(0.3, "least vertical extent of a kept blob", "m", low=0)
    min_top: float = setting(0.7, "least height of a kept blob's top above the floor", "m", low=0)
    join_m: float | None = setting(0.1, "components whose floor footprints come this close are one blob "
                                        "(none: no joining)", "m", low=0)
    max_gap_s: float = setting(3.0, "how long a track survives without its blob", "s", low=0)
    gate_m: float = setting(0.5, "a blob is matched to a track whose prediction lies within this", "m", above=0)
    gate_growth: float = setting(1.0, "the gate grows by this much per second a track is not seen", "m/s", low=0)
    claim_share: float = setting(0.2, "least share of a blob's cells near a track's prediction for the track to "
                                      "claim it", "share", above=0, high=1)
    merge_margin_m: float = setting(0.1, "margin of a track's box within which a merged blob's cells are its",
                                    "m", low=0)
    fragment_m: float = setting(0.5, "an unclaimed blob this close to a track is a fragment of it, not a new "
                                     "track", "m", low=0)
    min_share: float = setting(0.1, "least share of a merged blob's cells a claiming track must get", "share",
                               low=0, high=1)
    position_gain: float = setting(0.5, "alpha of the alpha-beta filter on each track's centroid", "gain",
                                   above=0, high=1)
    velocity_gain: float = setting(0.1, "beta of the alpha-beta filter on each track's velocity", "gain",
                                   above=0, high=1)


@dataclass(frozen=True)
class PixelsConfig(_Section):
    """Stage 2c: each tracked person's own pixels; shared pixels go to the nearest predicted
    body (the exclusion principle, ``occupose.grid.pixels``)."""

    _path = "pixels"
    reach: float = setting(0.1, "a body made of points reaches this far from them", "m", above=0)
    body_points: int = setting(4000, "about this many of a track's previous points make its body before it has "
                                     "a pose", "points", low=1)
    fallback: str = setting("horizontal", "distance used where no predicted body reaches a point",
                            choices=FALLBACK_NAMES)


@dataclass(frozen=True)
class StartConfig(_Section):
    """When a blob starts a person, and how (``occupose.pose.start``)."""

    _path = "start"
    min_top: float = setting(1.0, "the blob's own points reach at least this high", "m", low=0)
    min_points: int = setting(200, "the blob has at least this many observed points", "points", low=1)
    frames: int = setting(5, "frames in a row the blob must be person-like; its size is measured on them pooled",
                          "frames", low=1)
    min_fill: float = setting(0.25, "some camera sees the pixels fill at least this share of their box",
                              "share", low=0, high=1)
    fill_quantiles: tuple[float, float] = setting((5.0, 95.0), "the box is between these percentiles of the "
                                                               "pixels' columns and rows", "percent", low=0, high=100)
    border_px: int = setting(3, "pixels this close to the left, right or top image edge: not fully in view",
                             "pixels", low=0)
    border_count: int = setting(20, "... when at least this many of them are (a body cut by the edge has hundreds "
                                    "there; a few are stray readings)", "pixels", low=1)
    clearance: float = setting(0.5, "no start within this of a tracked person's pelvis (a piece of its blob)",
                               "m", low=0)
    headings: int = setting(12, "headings tried around the circle (the half facing the way walked, or the "
                                "camera)", "count", low=1)
    seat_share: float = setting(0.26, "seat height of the seated start, as a share of the stature", "share",
                                above=0, high=0.5)
    samples: int = setting(40, "random perturbations of each start candidate scored", "count", low=1)
    steps: int = setting(3, "filter steps on the first observation to settle the start", "count", low=0)
    spread_position: float = setting(0.05, "spread of the new particles' root x, y, z", "m", low=0)
    spread_heading: float = setting(0.15, "spread of the new particles' heading", "rad", low=0)
    spread_angle: float = setting(0.1, "spread of the new particles' joint angles", "rad", low=0)
    still_frames: int = setting(1, "on this many first frames, static structures shaped like a person (a head "
                                   "above wider shoulders) are taken for people standing still, whom the grid "
                                   "would take for background (0: people start only by moving)", "frames", low=0)
    still_floor: float = setting(0.15, "looking for still people, cells below this height are left out (a person "
                                       "stands on the floor)", "m", low=0)
    still_width: float = setting(1.0, "a still person's occupied cells span at most this much across the floor",
                                 "m", above=0)
    look_back_s: float = setting(1.0, "a new person is also tracked backwards over at most this much of its "
                                      "blob's frames before its start (0: no look-back)", "s", low=0, high=10)
    look_back_from: int = setting(10, "the backward run starts from the estimate this many frames after the start",
                                  "frames", low=0)


@dataclass(frozen=True)
class CarryConfig(_Section):
    """People out of sight (carried, suspended, back) and the way a person faces
    (``occupose.pose.person``)."""

    _path = "carry"
    frames: int = setting(15, "the walk of a person out of sight is measured on its last this many estimates",
                          "frames", low=2)
    max_speed: float = setting(0.067, "fastest a person out of sight is carried (2 m/s at 30 frames/s)",
                               "m/frame", low=0)
    max_anchor: float = setting(0.25, "largest pelvis-to-blob-centroid offset kept for placing a person who is "
                                      "back", "m", low=0)
    rejoin_m: float = setting(1.0, "a new blob track this close to a lost person's carried pelvis is that "
                                   "person's", "m", low=0)
    stand_dofs: tuple[str, ...] = setting(("left_hip", "left_knee", "right_hip", "right_knee"),
                                          "DOFs (by name prefix) that stand at rest while a walker is carried out "
                                          "of sight")
    walking_speed: float = setting(0.3, "faster than this a person walks: it starts facing the way it walks, and "
                                        "is turned round when it walks backwards", "m/s", low=0)
    backwards_deg: float = setting(135.0, "walking more than this from the way it faces is walking backwards",
                                   "deg", low=0, high=180)
    start_check_s: float = setting(2.0, "in its first seconds a person is turned round at walking_speed, later "
                                        "only at later_speed", "s", low=0)
    later_speed: float = setting(0.7, "speed above which a person is turned round after start_check_s", "m/s",
                                 low=0)
    upright: float = setting(0.85, "a move counts as a walk (for the turn round and the walking prior) only "
                                   "while the pelvis stays at least this share of its standing height over the "
                                   "frames measured: a person sitting down steps backwards", "share",
                             low=0, high=1)
    walk_frames: int = setting(15, "frames over which the way walked is measured for the walking prior",
                               "frames", low=2)
    walk_prior: float = setting(1.0, "what facing backwards costs at full walking speed", "nats", low=0)
    walk_from: float = setting(0.5, "speed from which the walking prior starts (slower: standing)", "m/s", low=0)
    walk_ramp: float = setting(0.4, "speed range over which the walking prior ramps up to full weight", "m/s",
                               above=0)
    twin: bool = setting(False, "compare each estimate with its twin facing the other way and turn to the twin "
                                "when it explains the points better for long enough (off until measured on the "
                                "catalogue and the randomized benchmark)")
    twin_window_s: float = setting(1.0, "the estimate's twin facing the other way (its joints relabelled left "
                                        "for right) is compared with it over this long", "s", above=0)
    twin_every: int = setting(3, "the twin is made and compared every this many estimates (making it costs a "
                                 "least-squares fit, about 5 ms)", "estimates", low=1)
    twin_share: float = setting(0.8, "the estimate turns to its twin when the twin explains the points better "
                                     "in at least this share of the window's comparisons", "share",
                                low=0.5, high=1)
    start_twin_s: float = setting(1.5, "over a new person's first this many seconds, until it walks faster than "
                                       "walking_speed, its estimate is compared with its twin (whatever twin says) "
                                       "to settle the way it faces; 0: never",
                                  "s", low=0)
    start_twin_count: int = setting(5, "the way a new person faces is settled on these comparisons (one every "
                                       "twin_every estimates) when there are at least this many",
                                    "comparisons", low=2)
    start_twin_t: float = setting(2.0, "... by the t statistic of the twin's gains in log-likelihood over the "
                                       "estimate: the twin is taken at this or more, the estimate kept at minus "
                                       "this or less; in between nothing is settled", "", above=0)


@dataclass(frozen=True)
class ShapeConfig(_Section):
    """Learning a person's stature, neck and shoulders from its first estimates
    (``occupose.pose.person``)."""

    _path = "shape"
    learn: bool = setting(True, "measure the neck height and shoulder width on estimates seen from the front or "
                                "back and resize the model once (full model only)")
    frames: int = setting(6, "measurements of neck and shoulders before the model is resized", "frames", low=1)
    lean: float = setting(0.3, "only estimates leaning less than this are measured", "rad", low=0)
    level_deg: float = setting(35.0, "only cameras looking down at most this much measure", "deg", low=0, high=90)
    frontal_deg: float = setting(37.0, "only views within this of facing the camera (or away) measure", "deg",
                                 low=0, high=90)
    stature_frames: int = setting(30, "the stature is measured again on the first this many upright estimates",
                                  "frames", low=1)
    stature_upright: float = setting(0.8, "upright: the pelvis at least this share of the legs' length above the "
                                          "floor", "share", low=0, high=1)
    stature_change: float = setting(0.05, "the model is rescaled when the stature measured again differs by more",
                                    "m", low=0)


@dataclass(frozen=True)
class SizeConfig(_Section):
    """Measuring a body's size on its points (``occupose.body.size``)."""

    _path = "size"
    top_rank: int = setting(10, "the top of the head is the this-th highest point", "rank", low=1)
    top_bias: float = setting(0.004, "added to that point's height (what the rank loses below the head's top)",
                              "m")
    chest_slice: tuple[float, float] = setting((0.70, 0.74), "the chest slice, as shares of the stature", "share",
                                               low=0, high=1)
    breadth_quantiles: tuple[float, float] = setting((0.003, 0.997), "a slice's breadth is between these "
                                                                      "quantiles along its principal axis",
                                                     "quantile", low=0, high=1)
    girth_range: tuple[float, float] = setting((0.85, 1.2), "the girth (radius scale) is clipped to this", "factor",
                                               above=0)
    min_slice_points: int = setting(30, "fewest chest-slice points for a girth (else girth 1)", "points", low=1)
    profile_slice: float = setting(0.01, "thickness of the breadth profile's slices", "m", above=0)
    profile_depth: float = setting(0.50, "depth of the breadth profile below the top of the head", "m", above=0)
    min_profile_points: int = setting(10, "fewest points of a profile slice with a breadth", "points", low=1)
    head_depth: float = setting(0.14, "the head is the widest slice within this of the top", "m", above=0)
    head_max: float = setting(0.25, "a head wider than this is a hand by the head", "m", above=0)
    chest_depth: tuple[float, float] = setting((0.30, 0.45), "the chest's breadth is the median between these "
                                                             "depths below the top", "m", low=0)
    shoulder_band: tuple[float, float] = setting((0.04, 0.12), "the shoulders' breadth is the median this far "
                                                               "below the neck", "m", low=0)
    shape_range: tuple[float, float] = setting((0.7, 1.5), "measured neck depths and shoulder widths stay within "
                                                           "these factors of the average adult's", "factor",
                                               above=0)


@dataclass(frozen=True)
class PoseConfig(_Section):
    """Stage 3 for one person: the body model and its particle filter (``occupose.pose``)."""

    _path = "pose"
    model: str = setting("auto", "body model; auto: upper for cameras looking steeply down, else full",
                         choices=MODEL_NAMES)
    steep_down_deg: float = setting(60.0, "a camera looking down more steeply than this is a ceiling camera",
                                    "deg", low=0, high=90)
    filter: str = setting("apf+ps", "particle filter", choices=FILTER_NAMES)
    particles: int = setting(200, "particles per person (their cost is bounded by limits.evaluations)", "particles",
                             low=1)
    layers: int | tuple[int, ...] | None = setting((2, 1, 2), "annealing layers: one number, or one per "
                                                              "partitioned-sampling stage (a model with another "
                                                              "number of stages gets the same total, spread from "
                                                              "the root down; none: the filter has no layers)",
                                                   "layers", low=1)
    survival: float = setting(0.5, "annealing: the share of particles each layer's weights keep alive",
                              "share", above=0, high=1)
    resampling: str = setting("systematic", "resampling scheme", choices=RESAMPLING_NAMES)
    shuffle: bool = setting(True, "part-based filter: shuffle the parts' resampled values among particles")
    part_weights: str = setting("chain", "part-based filter: what weights each part", choices=PART_WEIGHT_NAMES)
    likelihood: str = setting("points+free", "observation model", choices=LIKELIHOOD_NAMES)
    no_return_seen: bool = setting(False, "a pixel that has measured nothing for grid.no_return_after frames in a "
                                          "row counts, for the pose stage, as seeing through to the camera's far "
                                          "range (a body part drawn over it is in free space)")
    max_points: int = setting(1000, "most observed points per person and frame given to the likelihood", "points",
                              low=1)
    gate_m: float = setting(0.25, "points farther than this from the predicted body are left out", "m", above=0)
    gate_keep: float = setting(0.5, "a camera's points are all kept when the gate would keep fewer than this "
                                    "share", "share", low=0, high=1)
    upper_cut: float = setting(0.5, "the upper-body model sees only points above this share of the stature",
                               "share", low=0, high=1)
    velocity_damping: float = setting(0.8, "share of the root's last motion added to every particle before a step",
                                      "share", low=0, high=1)
    proposal_share: float = setting(0.1, "share of the particles given to each limb proposal", "share", low=0,
                                    high=0.99)

    def calls(self, stages: int) -> int:
        """Likelihood calls of the filter per frame (each evaluates every particle) for a
        body model of ``stages`` partitioned-sampling stages (3 full, 2 upper)."""
        if self.filter == "apf":
            return self.layers
        if self.filter == "apf+ps":
            return sum(self.layers) if isinstance(self.layers, tuple) else self.layers * stages
        return stages if self.filter == "ps" else 1

    def _check(self) -> None:
        if self.filter in ("apf", "apf+ps") and self.layers is None:
            raise ConfigError(f"pose.layers must be set for the {self.filter!r} filter (it anneals)")
        if self.filter not in ("apf", "apf+ps") and self.layers is not None:
            raise ConfigError(f"pose.layers must be none for the {self.filter!r} filter (it has no annealing "
                              f"layers), got {self.layers!r}")
        if isinstance(self.layers, tuple) and len(self.layers) not in (2, 3):
            raise ConfigError(f"pose.layers must hold one number per partitioned-sampling stage (3 for the full "
                              f"model: the root, the head and arms, the legs; 2 for the upper model: the root, the "
                              f"rest), got {len(self.layers)}: {list(self.layers)}")
        if self.filter == "apf" and isinstance(self.layers, tuple):
            raise ConfigError(f"pose.layers must be one number for the 'apf' filter (it has one stage), "
                              f"got {list(self.layers)}")


#: Likelihood evaluations per person and frame of method ``ours`` (200 particles x 5 layers).
_OURS_EVALUATIONS = PoseConfig().particles * PoseConfig().calls(3)


def _layers_text(layers: int | tuple[int, ...] | None) -> str:
    return "none" if layers is None else str(list(layers) if isinstance(layers, tuple) else layers)


@dataclass(frozen=True)
class DiffusionConfig(_Section):
    """The filter's random walk per frame at 30 frames/s, by DOF kind (scaled by 30 / fps;
    ``occupose.body.dynamics``)."""

    _path = "diffusion"
    root_xy: float = setting(0.02, "pelvis x and y", "m", low=0)
    root_z: float = setting(0.01, "pelvis height", "m", low=0)
    heading: float = setting(0.05, "heading", "rad", low=0)
    trunk: float = setting(0.03, "trunk lean", "rad", low=0)
    neck: float = setting(0.04, "neck flexion and tilt", "rad", low=0)
    neck_twist: float = setting(0.02, "the head's turn about its axis", "rad", low=0)
    shoulder: float = setting(0.08, "shoulder angles", "rad", low=0)
    elbow: float = setting(0.10, "elbow", "rad", low=0)
    forearm_twist: float = setting(0.08, "forearm twist", "rad", low=0)
    hip: float = setting(0.06, "hip angles", "rad", low=0)
    knee: float = setting(0.08, "knee", "rad", low=0)


@dataclass(frozen=True)
class LikelihoodConfig(_Section):
    """Options of the likelihood terms (``occupose.likelihood``); each applies where its term
    is part of ``pose.likelihood``."""

    _path = "likelihood"
    points_scale: float = setting(0.01, "points term: exp(-mean point-to-model distance / scale)", "m", above=0)
    free_weight: float = setting(1.0, "free-space term: its weight", "factor", low=0)
    free_margin: float = setting(0.03, "free-space term: model surface this far beyond the measured depth is in "
                                       "empty space", "m", low=0)
    free_ramp: float = setting(0.05, "free-space term: the penalty ramps up over this depth", "m", above=0)
    free_noise: str = setting("structured_light", "free-space term: the noise model of its margin",
                              choices=NOISE_MODEL_NAMES)
    render_scale: float = setting(5.0, "render term: its scale", "factor", above=0)
    render_truncation: float = setting(0.1, "render term: depth differences are truncated at this", "m", above=0)
    render_stride: int = setting(4, "render term: every this-th pixel is compared", "pixels", low=1)
    color_scale: float = setting(1.0, "colour term: its scale", "factor", above=0)
    color_bins: int = setting(4, "colour term: histogram bins per channel", "bins", low=1, high=256)
    color_margin: float = setting(0.05, "colour term: depth margin of the samples it reads", "m", low=0)

    def options_for(self, name: str) -> dict:
        """The keyword options of the likelihood registered as ``name`` (a term, or terms
        joined by ``+``, whose options go per term)."""
        per_term = {
            "points": {"scale": self.points_scale},
            "free": {"weight": self.free_weight, "margin": self.free_margin, "ramp": self.free_ramp,
                     "noise": self.free_noise},
            "render": {"scale": self.render_scale, "truncation": self.render_truncation,
                       "stride": self.render_stride},
            "color": {"scale": self.color_scale, "bins": self.color_bins, "margin": self.color_margin},
        }
        terms = name.split("+")
        return dict(per_term[terms[0]]) if len(terms) == 1 else {term: dict(per_term[term]) for term in terms}


@dataclass(frozen=True)
class PriorConfig(_Section):
    """Prior terms of the pose problem (``occupose.pose.problem``)."""

    _path = "priors"
    floor: float | None = setting(0.0, "height of the floor (none: no floor, feet or reach terms)", "m")
    floor_slack: float = setting(0.03, "floor term: a part may reach this far below the floor for free", "m",
                                 low=0)
    floor_cost: float = setting(20.0, "floor term: cost per metre beyond", "nats/m", low=0)
    reach_slack: float = setting(0.05, "reach term: a hip (a legless model's head) may be this much higher than "
                                       "it reaches standing", "m", low=0)
    reach_cost: float = setting(50.0, "reach term: cost per metre beyond", "nats/m", low=0)
    foot_reach: float = setting(0.30, "feet term: an ankle may be this high above the floor for free", "m", low=0)
    foot_cost: float = setting(20.0, "feet term: cost per metre beyond", "nats/m", low=0)
    rest_points: int = setting(15, "hanging-arm term: an arm with fewer points nearest to it is unseen", "points",
                               low=0)
    rest_cost: float = setting(1.0, "hanging-arm term: what an unseen upper arm raised straight up costs", "nats",
                               low=0)


@dataclass(frozen=True)
class ProposalConfig(_Section):
    """Data-driven limb proposals (``occupose.pose.proposals``)."""

    _path = "proposals"
    unexplained: float = setting(0.05, "a point farther than this from the estimate is unexplained", "m", above=0)
    min_points: int = setting(10, "fewest unexplained points that make a limb proposal", "points", low=1)
    reach: float = setting(1.25, "reach of a limb beyond its two segments", "factor", above=0)
    foot_height: float = setting(0.2, "unexplained points below this height may be a foot", "m", above=0)
    foot_ahead: float = setting(0.07, "a foot's points lie this far ahead of its ankle", "m", low=0)
    foot_radius: float = setting(0.2, "a foot's points lie within this of their median", "m", above=0)
    foot_lost: float = setting(0.15, "a leg is proposed only when its foot is farther than this from its ankle",
                               "m", low=0)
    mirror_differ: float = setting(0.5, "a still person's legs are proposed as each other when they differ by "
                                        "more", "rad", low=0)
    mirror_bent: float = setting(0.15, "... and the hips are more than this below a straight leg's reach", "m",
                                 low=0)
    elbow_candidates: int = setting(8, "places tried for the elbow (knee) of a limb within reach", "count", low=1)


@dataclass(frozen=True)
class OcclusionConfig(_Section):
    """Body parts hidden by the scene (the first paper's III-D, ``occupose.pose.occlusion``)."""

    _path = "occlusion"
    enabled: bool = setting(True, "detect hidden parts and leave them out of the filter (full model only)")
    spheres: int = setting(5, "spheres per capsule tested for visibility", "count", low=1)
    margin: float = setting(0.1, "a sphere is hidden behind a measured surface nearer by more than this", "m",
                            low=0)
    resume_frames: int = setting(10, "a part visible again gets a wider search for this many frames", "frames",
                                 low=0)
    resume_scale: float = setting(3.0, "... its diffusion multiplied by this", "factor", low=1)
    plant_hip_max: float = setting(1.8, "hidden legs: hip flexions tried from 0 up to this", "rad", low=0)
    plant_hip_steps: int = setting(19, "hidden legs: hip flexions tried", "count", low=2)
    plant_knee_max: float = setting(2.2, "hidden legs: knee bends tried from 0 up to this", "rad", low=0)
    plant_knee_steps: int = setting(23, "hidden legs: knee bends tried", "count", low=2)


@dataclass(frozen=True)
class RecoverConfig(_Section):
    """The test of whether an estimate still explains its person's points, and the search
    again from scratch, kept only when it explains them better (``occupose.pose.person``,
    ``Person.recheck``)."""

    _path = "recover"
    enabled: bool = setting(False, "search again from scratch now and then, and soon after doubtful estimates "
                                   "(off: on the random scenes it made more runs worse than better)")
    every: int = setting(15, "search again after this many estimates", "frames", low=1)
    explained_m: float = setting(0.05, "a point is explained when at most this far from the estimated body's "
                                       "surface", "m", above=0)
    min_explained: float = setting(0.7, "an estimate explaining a smaller share of its person's points is doubtful",
                                   "share", low=0, high=1)
    frames: int = setting(3, "after this many doubtful estimates in a row, search again at once", "frames", low=1)
    cooldown: int = setting(5, "... but not within this many estimates of the last search", "frames", low=0)
    points: int = setting(500, "the person's points tested (evenly taken from all of them)", "points", low=1)
    samples: int = setting(10, "random perturbations of each candidate pose scored", "count", low=1)
    steps: int = setting(3, "filter steps settling the best of them", "count", low=1)


@dataclass(frozen=True)
class FloorConfig(_Section):
    """Placing a camera of a recording without a world pose from the floor seen in its first
    frames (``occupose.geometry.floor``, ``occupose.io.sources.place_from_floor``)."""

    _path = "floor"
    frames: int = setting(15, "first frames whose per-pixel median depth the floor is fitted to (a person moving "
                                "through them is left out)", "frames", low=1)
    points: int = setting(20000, "points of that median image the planes are fitted to (evenly taken)", "points",
                          low=3)
    iterations: int = setting(300, "RANSAC plane hypotheses per plane found", "count", low=1)
    planes: int = setting(5, "largest planes found, one after another, as floor candidates", "count", low=1)
    tolerance_m: float = setting(0.02, "a point lies on a plane within this ...", "m", above=0)
    tolerance_rel: float = setting(0.01, "... plus this share of its depth (sensor noise grows with depth)",
                                   "share", low=0)
    min_share: float = setting(0.05, "least share of the points on a plane that can be the floor", "share",
                               low=0, high=1)
    max_below: float = setting(0.02, "most share of the points beyond a floor candidate (nothing is seen below "
                                     "the floor)", "share", low=0, high=1)
    min_height: float = setting(0.1, "lowest camera height above a floor candidate", "m", low=0)
    max_height: float = setting(6.0, "highest camera height above a floor candidate", "m", above=0)
    image_up: float = setting(0.5, "without an IMU, a candidate's score is its share times this plus how far its "
                                   "normal points up the image (a camera is mounted image-up: the floor is "
                                   "toward the image's bottom or straight ahead, never at its top)", "", low=0)
    parallel_deg: float = setting(5.0, "a plane within this of the chosen floor's orientation and lower is the "
                                       "floor instead (the chosen one is a table top)", "deg", low=0, high=90)
    gravity_deg: float = setting(15.0, "with an IMU, the floor's normal lies within this of the measured up "
                                       "direction", "deg", low=0, high=90)


@dataclass(frozen=True)
class FitConfig(_Section):
    """Fitting the body to one depth frame, with no background model, no motion and maybe no
    floor (``occupose.pose.single``, ``occupose fit``)."""

    _path = "fit"
    background_m: float = setting(0.05, "with a background image, a pixel is the background unless it is at least "
                                        "this much nearer", "m", above=0)
    floor_m: float = setting(0.05, "with a floor, points lower than this above it are the floor", "m", low=0)
    floor_span: float = setting(1.0, "a plane fitted to the frame is its floor only when its points span this much "
                                     "across it both ways (a chest seen from the front is a plane too)", "m", low=0)
    join_m: float = setting(0.1, "points in cells of this size that touch (26 neighbours) are one person", "m",
                            above=0)
    min_points: int = setting(1000, "a person has at least this many points", "points", low=1)
    min_height: float = setting(0.4, "... and spans at least this height (a hand held out towards the camera does "
                                     "not)", "m", low=0)
    min_part: int = setting(100, "a smaller group of at least this many points joins the nearest person ...",
                              "points", low=1)
    reach_m: float = setting(0.8, "... when within this of their points (a hand held out hides its forearm)", "m",
                             low=0)
    feet_height: float = setting(0.25, "with a floor, a person whose lowest point is below this has their legs in "
                                       "view (model auto: the full body)", "m", low=0)
    stature: float = setting(1.72, "stature taken when the feet are not in view (an average adult's)", "m",
                             above=1.0, high=2.2)
    steps: int = setting(15, "filter steps on the frame after the start search", "count", low=0)
    visible_m: float = setting(0.15, "a fitted joint in the image is visible when a point of its person is this "
                                     "near", "m", above=0)


@dataclass(frozen=True)
class LimitsConfig(_Section):
    """Bounds on what a run may cost and on what its cameras may be, checked before any work
    (``occupose.bounds``, ``occupose.grid.occupancy.spec_from_cameras``): a setting or a
    camera beyond them is refused with the estimate, instead of a hang, a MemoryError or an
    empty result. Each is far beyond every built-in scene, sensor preset and benchmark
    (``docs/notes/2026-12-04-bounds.md`` has the figures); raise one to go past it."""

    _path = "limits"
    grid_cells: int = setting(20_000_000, "most cells of the occupancy grid (about 72 bytes each with one or two "
                                          "cameras: 1.4 GB; 16 plus 20 per camera with more; the largest default "
                                          "grid of the scenes is 0.8 M cells, 12 M at grid.cell 0.02)", "cells", low=1)
    evaluations: int = setting(100_000, "most likelihood evaluations per person and frame, pose.particles times "
                                        "the filter's layers or stages (ours: 1000, ps: 6000; about 0.7 s a "
                                        "person and frame on one core at 1000 points)", "evaluations", low=1)
    image_pixels: int = setting(4096 * 4096, "most pixels of a camera's image (the largest preset has 0.37 M)",
                                "pixels", low=1)
    min_fps: float = setting(1.0, "slowest frame rate tracked (the motion between two frames outgrows the "
                                  "blob gate below it)", "frames/s", above=0)
    max_fps: float = setting(1000.0, "fastest frame rate tracked (depth sensors give at most 300; windows counted "
                                     "in frames grow with it)", "frames/s", above=0)
    ray_angle_deg: float = setting(75.0, "every pixel's ray lies within this of the optical axis (the presets "
                                         "reach 46; a principal point far outside the image or a tiny focal "
                                         "length goes beyond)", "deg", above=0, high=89.9)
    distance_m: float = setting(1000.0, "cameras are within this of the world origin (float32 positions lose "
                                        "0.06 m at 1e6 m)", "m", above=0)
    lowest_view_m: float = setting(0.5, "each camera's view within its far range comes down to at least this "
                                        "height (one that does not looks up, or its pose is inverted: it sees "
                                        "no floor and no legs; the scenes reach 0.05 m or lower)", "m", low=0)
    floor_margin: float = setting(0.1, "a measured point this far below the floor is below it", "m", low=0)
    below_floor_share: float = setting(0.5, "refused when, in a camera's first frame with measurements, a larger "
                                            "share of its points within range is below the floor (a wrong pose "
                                            "or depth_scale; the scenes have none)", "share", low=0, high=1)

    def _check(self) -> None:
        if self.min_fps > self.max_fps:
            raise ConfigError(f"limits.min_fps must be <= limits.max_fps, got {self.min_fps} > {self.max_fps}")


@dataclass(frozen=True)
class TrackerConfig(_Section):
    """Every setting of a tracking run (see the module docstring); the default is ``ours``."""

    grid: GridConfig = field(default_factory=GridConfig)
    blobs: BlobConfig = field(default_factory=BlobConfig)
    pixels: PixelsConfig = field(default_factory=PixelsConfig)
    start: StartConfig = field(default_factory=StartConfig)
    carry: CarryConfig = field(default_factory=CarryConfig)
    shape: ShapeConfig = field(default_factory=ShapeConfig)
    size: SizeConfig = field(default_factory=SizeConfig)
    pose: PoseConfig = field(default_factory=PoseConfig)
    diffusion: DiffusionConfig = field(default_factory=DiffusionConfig)
    likelihood: LikelihoodConfig = field(default_factory=LikelihoodConfig)
    priors: PriorConfig = field(default_factory=PriorConfig)
    proposals: ProposalConfig = field(default_factory=ProposalConfig)
    occlusion: OcclusionConfig = field(default_factory=OcclusionConfig)
    recover: RecoverConfig = field(default_factory=RecoverConfig)
    floor: FloorConfig = field(default_factory=FloorConfig)
    fit: FitConfig = field(default_factory=FitConfig)
    limits: LimitsConfig = field(default_factory=LimitsConfig)

    def _check(self) -> None:
        pose, stages = self.pose, 2 if self.pose.model == "upper" else 3  # auto: the full model's, the most
        evaluations = pose.particles * pose.calls(stages)
        if evaluations > self.limits.evaluations:
            raise ConfigError(
                f"pose.particles = {pose.particles} with the {pose.filter!r} filter's {pose.calls(stages)} "
                f"likelihood calls a frame (pose.layers = {_layers_text(pose.layers)}) gives {evaluations:,} "
                f"likelihood evaluations per person and frame, {evaluations / _OURS_EVALUATIONS:,.0f} times "
                f"method ours'; the bound limits.evaluations is {self.limits.evaluations:,}")

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], *, source: str = "config") -> TrackerConfig:
        """A config from plain data: an optional ``method`` (a name of :data:`METHODS`, the
        base; default ``ours``) and sections of fields to change, e.g.
        ``{"method": "apf", "pose": {"particles": 300}}``. Unknown sections or fields, and
        values of the wrong type, are a :class:`ConfigError` naming them and ``source``."""
        if not isinstance(data, Mapping):
            raise ConfigError(f"{source}: a config must be a table of sections, got {_describe(data)}")
        data = dict(data)
        try:
            base = method_config(data.pop("method", "ours"))
        except ConfigError as error:
            raise ConfigError(f"{source}: {error}") from None
        values = {}
        sections = cls._section_names()  # in their order: a message is the same from run to run
        for section, entries in data.items():
            if section not in sections:
                hint = " (the seed is no setting: give it with --seed, or seed= in Python)" if section == "seed" else ""
                raise ConfigError(f"{source}: unknown section {section!r}; valid: method, {', '.join(sections)}"
                                  f"{hint}")
            if not isinstance(entries, Mapping):
                raise ConfigError(f"{source}: section {section!r} must be a table of settings, got "
                                  f"{_describe(entries)}")
            values |= {f"{section}.{key}": value for key, value in entries.items()}
        try:
            return base.with_values(values)
        except ConfigError as error:
            raise ConfigError(f"{source}: {error}") from None

    @classmethod
    def from_file(cls, path: str | Path) -> TrackerConfig:
        """A config from a TOML (``.toml``) or JSON file of the keys :meth:`from_dict` takes."""
        return cls.from_dict(read_settings(path), source=str(path))

    def with_values(self, values: Mapping[str, Any]) -> TrackerConfig:
        """This config with ``values`` (dotted keys ``"section.field"``) changed, checked."""
        changed: dict[str, dict[str, Any]] = {}
        for key, value in values.items():
            section, _, name = key.partition(".")
            current = getattr(self, section, None) if section in self._section_names() else None
            if current is None:
                raise ConfigError(f"unknown section {section!r} in {key!r}; valid: {', '.join(self._section_names())}")
            if name not in {f.name for f in dataclasses.fields(current)}:
                valid = ", ".join(f.name for f in dataclasses.fields(current))
                raise ConfigError(f"unknown setting {key!r}; {section} has: {valid}")
            changed.setdefault(section, {})[name] = value
        return dataclasses.replace(self, **{s: dataclasses.replace(getattr(self, s), **v)
                                            for s, v in changed.items()})

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """Plain data (tuples as lists, none as None) that :meth:`from_dict` reads back equal."""
        return {s: {f.name: list(v) if isinstance(v := getattr(getattr(self, s), f.name), tuple) else v
                    for f in dataclasses.fields(getattr(self, s))} for s in self._section_names()}

    @classmethod
    def _section_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls))


def read_settings(path: str | Path) -> dict[str, Any]:
    """The table of settings in a TOML (``.toml``) or JSON file, unchecked (see
    :meth:`TrackerConfig.from_dict`); ConfigError naming the file when it cannot be read."""
    path = Path(path)
    try:
        text = path.read_text()
    except (OSError, UnicodeDecodeError) as error:
        raise ConfigError(f"{path}: cannot read the config ({getattr(error, 'strerror', None) or error})") from None
    try:
        data = tomllib.loads(text) if path.suffix == ".toml" else json.loads(text)
    except (ValueError, RecursionError) as error:
        kind = "TOML" if path.suffix == ".toml" else "JSON"
        raise ConfigError(f"{path}: not valid {kind} ({error})") from None
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: a config must be a table of sections, got {_describe(data)}")
    return data


def _methods() -> dict[str, TrackerConfig]:
    ours = TrackerConfig()
    no_occlusion = OcclusionConfig(enabled=False)
    return {
        "ours": ours,
        "apf": dataclasses.replace(ours, pose=PoseConfig(filter="apf", particles=200, layers=10),
                                   occlusion=no_occlusion),
        "ps": dataclasses.replace(ours, pose=PoseConfig(filter="ps", particles=2000, layers=None),
                                  occlusion=no_occlusion),
        "part-based": dataclasses.replace(ours, pose=PoseConfig(filter="part-based", particles=1000, layers=None,
                                                                model="upper"), occlusion=no_occlusion),
    }


#: The methods of the papers as configs. ``ours``: the first paper's annealed + partitioned
#: filter (200 particles, its 5 layers spread 2, 1, 2 over the root, the head and arms, the
#: legs: 1000 likelihood evaluations a frame) with occlusion handling; ``apf`` (200 x 10
#: layers) and ``ps`` (2000 x 3 stages) its baselines without occlusion handling;
#: ``part-based`` the second paper's upper-body filter (1000 particles).
METHODS: dict[str, TrackerConfig] = _methods()


def method_config(name: str) -> TrackerConfig:
    """The config of the method called ``name`` (:data:`METHODS`); ConfigError listing the names otherwise."""
    if not isinstance(name, str) or name not in METHODS:
        raise ConfigError(f"unknown method {name!r}; valid names: {', '.join(METHODS)}")
    return METHODS[name]


def as_config(config: TrackerConfig | str) -> TrackerConfig:
    """``config`` itself, or the config of the method it names; ConfigError naming the
    argument for anything else (settings as a dict go through :meth:`TrackerConfig.from_dict`)."""
    config = method_config(config) if isinstance(config, str) else config
    if not isinstance(config, TrackerConfig):
        raise ConfigError(f"config must be a TrackerConfig or a method name, got {type(config).__name__} "
                          f"(settings as a dict: TrackerConfig.from_dict)")
    return config
