"""When a blob starts a person, and the pose it starts in.

A blob starts a person once its own points (the pixels given to it, not those of the
people beside it) have been person-like for ``start.frames`` frames in a row: tall enough
(``start.min_top``), enough of them (``start.min_points``), fully in view of some camera
(:func:`occupose.pose.views.at_border`) and seen by some camera as a solid silhouette
(:func:`silhouette_fill`; a wall's scattered readings in a person's shadow from a second
camera are not). Its body size is measured on those frames' points pooled, and the start
pose is the best of :func:`occupose.pose.search.start_candidates` (standing and seated, at
the headings of :func:`start_headings`) and of random perturbations of them, settled by a
few filter steps. The settings are the fields of :class:`occupose.config.StartConfig`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from occupose.body import body_model, dims_from_observation
from occupose.body.size import breadth_profile, neck_and_shoulders, top_height
from occupose.camera import Camera, points_from_depth
from occupose.config import SizeConfig, StartConfig, TrackerConfig
from occupose.geometry.angles import wrap_angle
from occupose.grid.blobs import blobs_from_mask
from occupose.grid.occupancy import O, cells_from_depth
from occupose.grid.pixels import PersonPixels
from occupose.grid.spec import GridSpec
from occupose.likelihood import Observation, observation_from_views
from occupose.pose.person import Person
from occupose.pose.search import best_sample, start_candidates, start_spread
from occupose.pose.views import at_border, views_from_pixels


def still_people(states: np.ndarray, spec: GridSpec, depths: Mapping[str, np.ndarray], cameras: Sequence[Camera],
                 config: StartConfig, size: SizeConfig, join_m: float | None = None) -> np.ndarray:
    """(nx, ny, nz) bool: the occupied cells of the static structures shaped like a person.

    The grid learns the background from the first frame, so a person in view and still
    from then on is background to it, and only what moves starts a person. Here every
    connected group of cells in state O above ``config.still_floor`` (so that a person
    standing on the floor is apart from it) whose top is between ``config.min_top`` and
    the grid's top, that spans at most ``config.still_width`` across the floor, and whose
    points (those of the camera that sees most of them) show a head above wider
    shoulders (:func:`occupose.body.size.neck_and_shoulders`: a table, a chair, a cabinet
    or a wall do not) is taken for a person. The groups are the connected ones, and also
    those joined as blobs are (``join_m``, metres, :func:`occupose.grid.blobs.blobs_from_mask`;
    None: only the connected ones): from a ceiling camera the occupied cells of a still
    person are the top of the head and the shoulders, apart, while a person standing
    behind a counter joins it.

    states : (nx, ny, nz) uint8 grid states; depths : camera name -> (H, W) float32 metres
    """
    occupied = states == O
    occupied[:, :, :int(round((config.still_floor - spec.origin[2]) / spec.cell))] = False
    found = np.zeros(spec.shape, bool)
    for join in dict.fromkeys((None, join_m)):
        labels, blobs = blobs_from_mask(occupied, spec, min_cells=1, min_height=0.0, min_top=config.min_top,
                                        join_m=join)
        candidates = [b for b in blobs if np.all(b.high[:2] - b.low[:2] <= config.still_width + 1e-9)
                      and b.high[2] < spec.high[2] - 1e-9]  # not reaching the grid's top (a wall, a pillar)
        for b in _shaped_like_a_person(candidates, labels, spec, depths, cameras, size):
            found.reshape(-1)[b.cells] = True
    return found


def _shaped_like_a_person(candidates: list, labels: np.ndarray, spec: GridSpec, depths: Mapping[str, np.ndarray],
                          cameras: Sequence[Camera], size: SizeConfig) -> list:
    """The blobs of ``candidates`` (of the label volume ``labels``) whose points, those of
    the camera that sees most of them, show a head above wider shoulders."""
    if not candidates:
        return []
    flat = labels.reshape(-1)
    points_of = {b.label: [] for b in candidates}
    for camera in cameras:
        cell = cells_from_depth(depths[camera.name], camera, spec).reshape(-1)
        points, pixels = points_from_depth(depths[camera.name], camera)
        label = np.where(cell[pixels] >= 0, flat[np.maximum(cell[pixels], 0)], 0)
        for b in candidates:
            points_of[b.label].append(points[label == b.label])
    return [b for b in candidates if len(points := max(points_of[b.label], key=len)) >= size.top_rank
            and neck_and_shoulders(breadth_profile(points, size), size) is not None]


def person_like(pixels: PersonPixels, cameras: Sequence[Camera], config: StartConfig, top_rank: int) -> bool:
    """Whether a blob's own pixels may start a person this frame (the module docstring);
    ``top_rank`` : the rank of the point taken as the top (:class:`occupose.config.SizeConfig`)."""
    points = pixels.points
    return (len(points) >= config.min_points and top_height(points[:, 2], top_rank) >= config.min_top
            and not at_border(pixels, cameras, config.border_px, config.border_count)
            and max(silhouette_fill(pixels.pixels[c.name], c.width, config.fill_quantiles) for c in cameras)
            >= config.min_fill)


def silhouette_fill(pixels: np.ndarray, width: int, quantiles: tuple[float, float] = StartConfig.fill_quantiles
                    ) -> float:
    """Share of the image box between the ``quantiles`` (percent) of the pixels' columns and
    rows that the pixels fill (0 for none). A person fills 0.55-0.8 of it (0.12 while cut by
    the image's edge); a wall's noisy readings in a person's shadow scatter over 0.01-0.08.

    pixels : (N,) int, flat indices ``v * width + u`` of one camera's pixels, distinct
    """
    if len(pixels) == 0:
        return 0.0
    rows, columns = np.divmod(np.asarray(pixels), width)
    (u0, u1), (v0, v1) = np.percentile(columns, quantiles), np.percentile(rows, quantiles)
    inside = (columns >= u0) & (columns <= u1) & (rows >= v0) & (rows <= v1)
    return float(np.count_nonzero(inside) / ((np.floor(u1) - np.ceil(u0) + 1) * (np.floor(v1) - np.ceil(v0) + 1)))


def start_headings(velocity: np.ndarray, centroid: np.ndarray, camera: Camera, count: int = StartConfig.headings,
                   walking_speed: float = 0.3) -> np.ndarray:
    """The headings of ``count`` around the circle a person may start with, radians: those
    within 90 degrees of where they walk (``velocity`` (2,) m/s, when faster than
    ``walking_speed`` m/s), else of the direction towards ``camera`` from ``centroid`` (3,)
    metres.

    A body of round cones fits its points about as well facing either way (front and
    back differ little in depth), so the likelihood alone picks the wrong half turn about
    as often as the right one, which swaps left and right for good; people mostly face
    where they walk, and a person standing in view of a camera more often faces it.
    """
    headings = np.linspace(-np.pi, np.pi, count, endpoint=False)
    if np.hypot(*velocity) > walking_speed:
        facing = np.arctan2(velocity[1], velocity[0])
    else:
        to_camera = camera.world_from_camera[:2, 3] - centroid[:2]
        facing = np.arctan2(to_camera[1], to_camera[0])
    off = wrap_angle(headings - facing)
    return headings[np.abs(off) < np.pi / 2 + 1e-9]


def start_person(points: np.ndarray, pixels: PersonPixels, depths: Mapping[str, np.ndarray], centroid: np.ndarray,
                 velocity: np.ndarray, cameras: Sequence[Camera], model_name: str, config: TrackerConfig, fps: float,
                 rng: np.random.Generator, area: tuple[np.ndarray, np.ndarray] | None = None) -> Person:
    """A new person from its blob's pooled points (N, 3) world metres (its size) and this
    frame's ``pixels``: the best start candidate, settled by ``start.steps`` filter steps.

    depths : camera name -> (H, W) float32 metres; centroid : (3,) metres, the blob's
    centroid this frame; velocity : (2,) m/s, its track's horizontal velocity;
    model_name : "full" or "upper"; rng : the person's random generator; area : as
    :class:`occupose.pose.person.Person`'s
    """
    size = dims_from_observation(points, size=config.size)
    person = Person(body_model(model_name, size.dims, size.girth), config, fps, rng, cameras, area=area)
    best, _ = search_start(person, pixels, depths, velocity, cameras, config.start.steps)
    person.centroid = np.asarray(centroid, float)
    person.settle(best, velocity)
    return person


def search_start(person: Person, pixels: PersonPixels, depths: Mapping[str, np.ndarray], velocity: np.ndarray,
                 cameras: Sequence[Camera], steps: int) -> tuple[np.ndarray, Observation]:
    """The pose (D,) of a ``person`` without one (its model sized) that best explains its
    ``pixels``, and the observation made of them: the best of the start candidates at the
    headings of :func:`start_headings` and of their random perturbations, then ``steps``
    steps of its filter on that observation. Settings from ``person.config.start``.

    depths : camera name -> (H, W) float32 metres; velocity : (2,) m/s, its horizontal velocity
    """
    config = person.config
    seen = observation_from_views(views_from_pixels(pixels, depths, cameras, person.model, config.pose),
                                  config.pose.max_points)
    problem = person.problem
    problem.set_observation(seen)
    centre = np.mean(pixels.points, axis=0)
    headings = start_headings(velocity, centre, cameras[0], config.start.headings, config.carry.walking_speed)
    candidates = start_candidates(person.model, centre, headings, config.start.seat_share)
    spread = start_spread(person.model, config.start)
    best = best_sample(problem, candidates, spread, config.start.samples, person.estimator.filter.rng)
    person.estimator.initialise(best, spread)
    for _ in range(steps):
        best = person.estimator.step(seen)
    return best, seen
