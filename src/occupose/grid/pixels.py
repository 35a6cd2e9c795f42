"""Stage 2c: each tracked person's own observation, the depth pixels and 3D points of its blob.

As in the first paper's Fig. 2(d), every measured depth pixel is back-projected to a 3D
point, the point falls in a grid cell, the cell's label names a blob and the blob a track
(the pixel-to-cell step is stage 1's `occupose.grid.occupancy.cells_from_depth`, which
also gives a point on a silhouette edge, in a cell the grid holds empty, to its nearest
occupied neighbour). Pixels whose cell is in no tracked blob belong to nobody, so only the
window of each image in which the tracks' cells (and their neighbours) are seen is read
(`window_of_box`): the pass costs in proportion to the people's share of the image.

Where tracks share a blob (merged people) the pixel goes to the nearest predicted body:
the exclusion principle of the second paper (eq. 5, a(u) = argmin_t d(u, x_t)).
``predicted`` maps a track id to a distance function ``f(points (N, 3)) -> (N,)`` metres:
the pose stage passes the distance to its predicted body model; before there is one,
`predicted_from_tracks` makes bodies of the previous frame's observations (the best of the
fallbacks measured: ~99 % of a merged top-view pair's pixels right, against ~97 % for the
centroid distance). Where a track has no predicted body, or its body does not reach a
point (``inf``, see `distance_to_points`), its distance is the ``fallback`` distance from
its centre (`FALLBACKS`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial import cKDTree

from occupose.camera import Camera, pixels_from_points, points_at_pixels
from occupose.config import PixelsConfig
from occupose.grid.blobs import Blob
from occupose.grid.occupancy import E, M, cells_from_depth
from occupose.grid.spec import GridSpec
from occupose.grid.tracking import TrackState

DistanceFunction = Callable[[np.ndarray], np.ndarray]

_MAX_TRACKS = 62  # tracks are bits of an int64 code
#: Default search radius of `distance_to_points`, metres.
REACH = PixelsConfig.reach
#: `predicted_from_tracks` keeps about this many points of each previous observation.
BODY_POINTS = PixelsConfig.body_points


def _horizontal(points: np.ndarray, center: np.ndarray) -> np.ndarray:
    return np.hypot(points[:, 0] - center[0], points[:, 1] - center[1])


def _euclidean(points: np.ndarray, center: np.ndarray) -> np.ndarray:
    return np.linalg.norm(points - center, axis=1)


#: Fallback distances ``f(points (N, 3), center (3,)) -> (N,)`` metres, from a track's centre:
#: "horizontal" is the distance to the vertical line through the centre (a standing body's
#: axis); "euclidean" the straight 3D distance.
FALLBACKS: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] = {
    "horizontal": _horizontal,
    "euclidean": _euclidean,
}


@dataclass(frozen=True, eq=False)
class PersonPixels:
    """The depth data of one tracked person in one frame.

    track_id : int
    pixels : camera name -> (N_c,) int64 flat pixel indices ``v * W + u``, increasing
    camera_points : camera name -> (N_c, 3) float64, metres, world frame, the pixels' points
    """

    track_id: int
    pixels: dict[str, np.ndarray]
    camera_points: dict[str, np.ndarray]

    @property
    def points(self) -> np.ndarray:
        """(N, 3) float64, metres, world frame: every camera's points, in camera order."""
        return np.concatenate(list(self.camera_points.values())) if self.camera_points else np.zeros((0, 3))


def distance_to_points(reference: np.ndarray, *, reach: float = REACH) -> DistanceFunction:
    """A predicted body given as points: ``f(points (N, 3)) -> (N,)`` distance to the nearest, metres.

    reference : (M, 3) float, metres, world frame, M >= 1 (e.g. a track's last observation)
    reach : float, metres; farther points get ``inf`` (a k-d tree's nearest-neighbour search
        from far off a dense surface visits most of it, so the search stops there), for
        which `pixels_from_depth` uses the track's ``fallback`` distance
    """
    reference = np.asarray(reference, np.float64)
    if reference.ndim != 2 or reference.shape[1] != 3 or len(reference) == 0:
        raise ValueError(f"reference must be a non-empty (M, 3) array of points, got shape {reference.shape}")
    if not (np.isfinite(reach) and reach > 0):
        raise ValueError(f"reach must be a positive number of metres, got {reach!r}")
    tree = cKDTree(reference)
    return lambda points: tree.query(np.asarray(points, np.float64).reshape(-1, 3), distance_upper_bound=reach)[0]


def _check_inputs(depths, cameras, spec, labels, tracks):
    if not isinstance(spec, GridSpec):
        raise ValueError(f"spec must be a GridSpec, got {type(spec).__name__}")
    labels = np.asarray(labels)
    if labels.shape != spec.shape or not np.issubdtype(labels.dtype, np.integer):
        raise ValueError(f"labels must be an integer array of the grid's shape {spec.shape}, "
                         f"got {labels.dtype} {labels.shape}")
    cameras = list(cameras)
    if not all(isinstance(c, Camera) for c in cameras):
        raise ValueError(f"cameras must be Camera objects, got {[type(c).__name__ for c in cameras]}")
    if not isinstance(depths, Mapping) or set(depths) != {c.name for c in cameras}:
        raise ValueError(f"depths must map each camera name {[c.name for c in cameras]} to its depth image, "
                         f"got keys {list(depths) if isinstance(depths, Mapping) else type(depths).__name__}")
    if not isinstance(tracks, Mapping) or not all(
            isinstance(t, (int, np.integer)) and t > 0 and isinstance(b, Blob) for t, b in tracks.items()):
        raise ValueError("tracks must map positive int track ids to Blob objects (BlobTracker.update's result)")
    if len(tracks) > _MAX_TRACKS:
        raise ValueError(f"at most {_MAX_TRACKS} tracks per frame are supported, got {len(tracks)}")
    return labels, cameras


def _label_codes(labels: np.ndarray, tracks: Mapping[int, Blob], ids: list[int]) -> np.ndarray:
    """(L,) int64 bit code of each label value: bit k set when track ids[k] claims the label."""
    num_labels = max(int(labels.max()), max(max(b.labels) for b in tracks.values())) + 1
    codes = np.zeros(num_labels, np.int64)
    for k, tid in enumerate(ids):
        codes[list(tracks[tid].labels)] |= np.int64(1) << k
    return codes


def window_of_box(camera: Camera, low: np.ndarray, high: np.ndarray) -> tuple[int, int, int, int]:
    """The image rows and columns ``(v0, v1, u0, u1)`` (half-open, at least one pixel) outside
    of which no pixel's 3D point can lie in the box from ``low`` to ``high`` ((3,) world
    metres): the box's corners projected (a box in front of the camera projects into the
    convex hull of its corners' projections), with a pixel's margin for rounding; the whole
    image when a corner is not in front of the camera."""
    corners = np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1]) for z in (low[2], high[2])])
    uv, depth = pixels_from_points(corners, camera)
    if not np.all(depth > 1e-6):
        return 0, camera.height, 0, camera.width
    u0 = int(np.clip(np.floor(uv[:, 0].min()) - 1, 0, camera.width - 1))
    v0 = int(np.clip(np.floor(uv[:, 1].min()) - 1, 0, camera.height - 1))
    u1 = int(np.clip(np.ceil(uv[:, 0].max()) + 2, u0 + 1, camera.width))
    v1 = int(np.clip(np.ceil(uv[:, 1].max()) + 2, v0 + 1, camera.height))
    return v0, v1, u0, u1


def pixels_from_depth(
    depths: Mapping[str, np.ndarray],
    cameras: Sequence[Camera],
    spec: GridSpec,
    labels: np.ndarray,
    tracks: Mapping[int, Blob],
    *,
    states: np.ndarray | None = None,
    centers: Mapping[int, np.ndarray] | None = None,
    predicted: Mapping[int, DistanceFunction] | None = None,
    fallback: str = "horizontal",
) -> tuple[dict[int, PersonPixels], dict[str, np.ndarray]]:
    """Split the depth pixels of one frame among the tracked people.

    Parameters
    ----------
    depths : camera name -> (H, W) depth image (float metres or uint16 raw, 0 = none)
    cameras : the cameras of ``depths``
    spec : GridSpec of ``labels``
    labels : (nx, ny, nz) int, the label volume of `blobs_from_mask`
    tracks : ``{track_id: Blob}`` from `BlobTracker.update`; a blob's ``labels`` are the
        label values that are that track's (tracks sharing a merged blob share them)
    states : (nx, ny, nz) uint8 grid states (`OccupancyGrid.states`), or None. A point
        in a cell the grid holds empty lies on a silhouette edge and is moved to its
        nearest occupied (O or M) neighbour cell (`occupose.grid.occupancy.cells_from_depth`);
        without ``states`` the labelled cells stand for the occupied ones, so a point next
        to a blob joins it.
    centers : ``{track_id: (3,) metres}``, each track's body centre for the fallback
        distance; default each blob's centroid. Pass the tracker's per-track centroids
        (``TrackState.centroid``) so that tracks sharing a blob have their own.
    predicted : ``{track_id: f(points (N, 3)) -> (N,) metres}``, distance to each track's
        predicted body (exclusion principle); where a track has none, or it returns
        ``inf``, the track's ``fallback`` distance is used (see `predicted_from_tracks`
        for bodies made of the previous observations)
    fallback : name in `FALLBACKS`

    Returns
    -------
    observations : ``{track_id: PersonPixels}`` for every track in ``tracks``
    assigned : camera name -> (H, W) int32 image of the track id of each pixel, 0 = nobody
    """
    labels, cameras = _check_inputs(depths, cameras, spec, labels, tracks)
    if fallback not in FALLBACKS:
        raise ValueError(f"unknown fallback {fallback!r}; valid names: {sorted(FALLBACKS)}")
    ids = sorted(int(t) for t in tracks)
    centers = {t: np.asarray(b.centroid, float) for t, b in tracks.items()} | dict(centers or {})
    predicted = dict(predicted or {})
    if set(centers) - set(tracks) or set(predicted) - set(tracks):
        raise ValueError(f"centers and predicted may only name tracked ids {ids}, got "
                         f"{sorted(set(centers) - set(tracks))} {sorted(set(predicted) - set(tracks))}")
    assigned = {c.name: np.zeros((c.height, c.width), np.int32) for c in cameras}
    pixels_of = {tid: {} for tid in ids}
    points_of = {tid: {} for tid in ids}
    if not ids:
        return {}, assigned
    if states is None:
        states = np.where(labels > 0, M, E).astype(np.uint8)
    codes = _label_codes(labels, tracks, ids)
    labels = labels.astype(np.int32, copy=False)
    label_of_cell = labels.reshape(-1)
    # the tracks' cells and their neighbours (a point in an empty cell may join one): only
    # the pixels in each camera's window of that box can be anyone's
    low = np.min([b.low for b in tracks.values()], axis=0) - spec.cell
    high = np.max([b.high for b in tracks.values()], axis=0) + spec.cell
    within = (np.rint((low - spec.origin) / spec.cell), np.rint((high - spec.origin) / spec.cell) - 1)  # its cells
    for camera in cameras:
        depth = np.asarray(depths[camera.name])
        if depth.shape != (camera.height, camera.width):
            raise ValueError(f"depth image for camera {camera.name!r} must have shape ({camera.height}, "
                             f"{camera.width}), got {depth.shape}")
        v0, v1, u0, u1 = window_of_box(camera, low, high)
        window = depth[v0:v1, u0:u1]
        cropped = replace(camera, width=u1 - u0, height=v1 - v0, cx=camera.cx - u0,
                          cy=camera.cy - v0)  # the same rays: (u - u0) - (cx - u0) is u - cx exactly
        cell = cells_from_depth(window, cropped, spec, states, labels=labels, claims=codes, within=within).reshape(-1)
        local = np.flatnonzero(cell >= 0)  # the window's pixels in a tracked blob's cells
        points = points_at_pixels(window, local, cropped)
        pixels = (local // cropped.width + v0) * camera.width + local % cropped.width + u0
        code = codes[label_of_cell[cell[local]]]
        owner = np.zeros(pixels.size, np.int64)
        for k, tid in enumerate(ids):
            owner[code == (np.int64(1) << k)] = tid
        shared = np.flatnonzero((code & (code - 1)) != 0)
        if shared.size:
            owner[shared] = _nearest_track(points[shared], cell[local[shared]], code[shared], ids, predicted,
                                           lambda pts, tid: FALLBACKS[fallback](pts, centers[tid]), spec)
        assigned[camera.name].reshape(-1)[pixels] = owner
        for tid in ids:
            mine = owner == tid
            pixels_of[tid][camera.name] = pixels[mine]
            points_of[tid][camera.name] = points[mine]
    return {tid: PersonPixels(tid, pixels_of[tid], points_of[tid]) for tid in ids}, assigned


def _distances(points, code, ids, predicted, fallback) -> np.ndarray:
    """(N, T) distance of each point to each candidate track (inf for non-candidates): the
    track's predicted body where it reaches (finite), its fallback distance elsewhere."""
    distance = np.full((len(points), len(ids)), np.inf)
    for k, tid in enumerate(ids):
        rows = np.flatnonzero(code & (np.int64(1) << k))
        if rows.size == 0:
            continue
        d = np.full(rows.size, np.inf)
        if tid in predicted:
            d = np.asarray(predicted[tid](points[rows]), float).reshape(-1)
        unreached = ~np.isfinite(d)
        if unreached.any():
            d[unreached] = fallback(points[rows[unreached]], tid)
        distance[rows, k] = d
    return distance


def _nearest_track(points, cells, code, ids, predicted, fallback, spec: GridSpec) -> np.ndarray:
    """(N,) id of the nearest candidate track of each point (bits of ``code`` over ``ids``,
    the same for all points of a cell: ``cells`` are their flat cell indices), by `_distances`.

    The distances are first taken at the centres of the points' cells: a distance moves by
    at most the cell's half diagonal ``r`` inside a cell, so where the nearest track is
    nearer than the next by more than ``2 r`` every point of the cell is its (exact for
    1-Lipschitz distances; approximate where a body's reach ends inside the cell); only
    the points of the other cells are measured one by one.
    """
    ids_array = np.asarray(ids)
    owner = np.zeros(len(points), np.int64)
    where, first, inverse = np.unique(cells, return_index=True, return_inverse=True)
    centres = np.asarray(spec.origin) + spec.cell * (np.stack(np.unravel_index(where, spec.shape), axis=1) + 0.5)
    at_centre = _distances(centres, code[first], ids, predicted, fallback)
    ranked = np.sort(at_centre, axis=1)
    clear = ranked[:, 0] + spec.cell * np.sqrt(3.0) < (ranked[:, 1] if len(ids) > 1 else np.inf)
    decided = clear[inverse]
    owner[decided] = ids_array[np.argmin(at_centre, axis=1)][inverse[decided]]
    rest = np.flatnonzero(~decided)
    owner[rest] = ids_array[np.argmin(_distances(points[rest], code[rest], ids, predicted, fallback), axis=1)]
    return owner


def predicted_from_tracks(states: Mapping[int, TrackState], previous: Mapping[int, PersonPixels], fps: float,
                          ids=None, *, body_points: int = BODY_POINTS, reach: float = REACH
                          ) -> dict[int, DistanceFunction]:
    """Predicted bodies made of data, for the exclusion principle before a pose is known.

    Each track's body is its previous observation's points (about ``body_points`` of them)
    moved by its velocity for one frame, or, for a track without one, the centres of its
    own cells this frame (``TrackState.points``: the tracker's share of any merged blob);
    distances as `distance_to_points` (``inf`` beyond ``reach`` metres).

    states : ``BlobTracker.states``; previous : the last frame's observations; fps : float
    ids : track ids to give a body to (default: the tracks seen this frame)
    Returns ``{track_id: f(points (N, 3)) -> (N,) metres}`` for `pixels_from_depth`.
    """
    fps = float(fps)
    if not (np.isfinite(fps) and fps > 0):
        raise ValueError(f"fps must be a positive number, got {fps!r}")
    ids = [i for i, s in states.items() if s.blob is not None] if ids is None else list(ids)
    bodies = {}
    for tid in ids:
        state = states[tid]
        before = previous.get(tid)
        if before is not None and len(before.points):
            moved = before.points[::max(1, len(before.points) // body_points)].copy()
            moved[:, :2] += state.velocity / fps
            bodies[tid] = distance_to_points(moved, reach=reach)
        elif len(state.points):
            bodies[tid] = distance_to_points(state.points, reach=reach)
    return bodies
