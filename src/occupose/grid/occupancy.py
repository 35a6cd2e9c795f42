"""Stage 1: the occupancy grid, a three-state HMM per cell, and what the cameras can see.

Every cell of a :class:`~occupose.grid.spec.GridSpec` runs a hidden Markov model with the
states of the first paper (section III-A): ``O`` occupied by a static object, ``M``
occupied by a moving object, ``E`` empty. Each frame, every depth image is read at the
pixel the cell centre projects to (found once, when the grid is made: the cameras do not
move); with ``l`` the centre's depth along that camera's optical axis and ``d`` the
measured depth at its pixel, ``epsilon = d - l`` gives the observation function
(the paper's Fig. 3, :func:`observation_function`), a plateau as wide as the cell with
edges blurred by the sensor's depth noise::

    f(epsilon) = p_occ                                              |epsilon| <= h   (surface in the cell: occupied)
                 p_free + (p_occ - p_free) exp(-(epsilon - h)^2 / 2 w^2)   epsilon > h      (seen through: empty)
                 0.5 + (p_occ - 0.5) exp(-(epsilon + h)^2 / 2 w^2)         epsilon < -h     (hidden: no information)
                 0.5 where d is 0 or the centre is outside the image or behind the camera

with ``h`` half the cell's extent along the optical axis, ``cell / 2 * (|r_x| + |r_y| + |r_z|)``
for the camera's viewing direction ``r`` in world axes, and ``w = tail_width * s`` where ``s``
is the sensor's random depth error at that distance (:func:`occupose.sensors.depth_std`
of the camera's noise model; ``tail_width`` 2 by default). The tails stop at ``band = h + 3 w``,
beyond which f is exactly ``p_free`` or 0.5 (the tail is down to 1 % there). A cell is
*visible* from a camera when ``epsilon >= -band`` (in front of or on the measured surface,
within the noise) and *hidden* when ``epsilon < -band``.

Why blurred edges, and why twice the noise: a cell whose centre lies near the edge of the
occupied plateau gets "occupied" and "free" readings by turns as the noise moves the
surface across it; every run of free readings makes it E and the next occupied one M, so
a noisy wall grows a flickering layer of "moving" cells. In ``no_occlusion`` (Kinect v1,
rear wall at 4.2 m) a hard step at ``h + 3 s`` gave about 1500 such cells and 1300 false
foreground pixels per frame; tails of width ``s`` still about 480 cells, because the Kinect
v1 quantises depth in steps of 5.4 cm at 4.2 m (against s = 2.9 cm there), so the readings
of one surface fall on two or three levels about 2 s apart; tails of width ``2 s`` leave
about 20 cells (25 pixels) and make readings near the edge close to uninformative.

The states' likelihoods are ``B = (f, f, 1 - f)`` (O and M look alike: the aliasing the HMM
resolves over time); the likelihoods of several cameras multiply, and a camera that does
not cover a cell adds nothing.

A deviation from the paper (``no_return = 1`` is its model): a pixel that measures
nothing (d = 0) while the cell centre is nearer than the camera's far range (``max_range``)
is evidence against a static surface in the cell, which would have returned a reading:
its likelihoods are ``B = (no_return, 1, 1)``. Such a pixel counts only once it has
measured nothing for ``no_return_after`` frames in a row (``returnless``): a background
beyond range returns nothing in every frame, whereas the dropouts of a surface (dark
cloth, glancing angles, the sensor's worst-case noise) come and go, and in their frames
would take O's share from the surface's cells before these settle as static.
M keeps 1, as E: a moving person's dropouts (dark hair, a glancing surface) last a frame
or two and cut no holes. Without it, space in front of a background beyond the sensor's
range is never observed and keeps the initial distribution's O share, and a person who
walks into it is static from their first frame there (O wins the first occupied reading,
since E -> M carries only ``beta`` of E). With ``no_return = 0.5`` the O share of such a
cell halves every frame, so after ten frames a person walking in is moving, as over a
floor the camera sees (docs/notes/2026-12-07-never-returned-cells.md). A cell whose MAP
state is O takes no such factor, as it takes ``alpha = 0`` when no camera sees it: the
readings of a static surface that come and go (edges in time-of-flight images, walls near
the range limit) do not turn it into a flickering "moving" layer. On the randomized
benchmark, counting every missing reading harmed the top views and scenes with their
background in range; counting those of 15 frames in a row (the default) does not, and
keeps the gains before a background beyond range (docs/results.md, "A missing reading as
evidence").

Transition matrix (rows: state at t-1, columns: state at t, order O, M, E), the paper's
Fig. 4 with its extra M -> O transition ``psi``::

          O        M              E
    O  [ 1-alpha   0              alpha   ]   static object removed (a chair carried away)
    M  [ psi       1-gamma-psi    gamma   ]   a moving object leaves; rarely, it settles (psi)
    E  [ 0         beta           1-beta  ]   something enters a free cell: it is moving

There is no E -> O (a new object is moving first) and no O -> M (a static object starts
moving by leaving its cells, O -> E, and entering others, E -> M). Forward update
``Q_t ~ (Q_{t-1}^T A) o B_t``, normalised; the cell's state is the MAP of ``Q_t``.

Our one change to the paper's model: a cell in state O (its MAP) that no camera sees
(hidden behind a measured surface or unobserved, so ``B_t`` carries no information) steps
with ``alpha = 0``: a static object is not removed while nobody can see it. With the
paper's matrix a wall behind a person who stands in front of it for ``ln 2 / alpha`` = 69
frames leaks to E, and when the person walks away the wall reappears from E as a *moving*
object for another 77 frames: a ghost blob where the person stood (a fourth "person" at
the back wall in the tracker's three-people benchmark). Something put down while hidden
still enters through E -> M, and something taken away while hidden is emptied as soon as a
camera sees through its cells. Cells never seen occupied (MAP E, e.g. hidden from the
first frame, with the initial distribution's O share) leak as in the paper, so a person
who later walks into space that was never seen is not taken for background.

How long until something that moved becomes background again. O and M always have the
same likelihood, so their posterior ratio ``r = P(O) / P(M)`` does not depend on how
strongly the cell is seen occupied, only on the flows into O and M. While a cell is seen
occupied, O receives ``(1 - alpha) O + psi M`` and M receives ``(1 - gamma - psi) M + beta E``,
where the empty share settles within a few frames at ``E = e M`` with ``e`` the positive root
of ``beta e^2 + (1 - gamma - psi - k (1 - beta)) e - k gamma = 0``, ``k = (1 - p_occ) / p_occ``
(E receives ``(1 - p_occ) (gamma M + (1 - beta) E)`` against M's ``p_occ (...)``). So::

    r_{t+1} = a r_t + b,   a = (1 - alpha) / (1 - gamma - psi + beta e),   b = psi / (1 - gamma - psi + beta e)

A cell entered from E starts at ``r_0 = 0`` (no E -> O), so ``r_t = b (a^t - 1) / (a - 1)``, and
its MAP turns from M to O when ``r_t > 1``::

    T = ln(1 + (a - 1) / b) / ln(a) = ln(1 + (gamma - alpha + psi - beta e) / psi) / ln(a)
      ~ (-ln psi + ln(gamma - alpha - beta e)) / ln(a)

For the defaults (alpha 0.01, beta 0.1, gamma 0.4, psi e^-38, p_occ 0.9): ``e = 0.087``,
``a = 1.626``, ``T = (38 - 0.96) / 0.486 = 76.2`` frames (:func:`frames_until_static`), 2.5 s
at 30 fps; one more frame passes while the cell enters (E -> M), so a cell first seen
occupied at frame ``t0`` is O from frame ``t0 + 77`` (a single-cell filter run gives exactly
that). Without the E share (``e = 0``) the figure would be 74.0. The same holds for a
person who stands perfectly still: after ``T`` frames they are background, unless the
tracker holds their cells (``hold`` of :meth:`OccupancyGrid.update`).

Initial distribution (``initial``, default ``(0.4, 0, 0.6)`` for O, M, E). One frame
cannot tell a static object from a moving one, and the ratio argument above shows that the
choice only matters for the first few frames: a cell occupied from the first frame on has
``r_t = r_0 a^t``, so whatever ``r_0 > 0`` is, it is O after ``-ln(r_0) / ln(a)`` frames and
stays O as long as it stays occupied; a person who walks is extracted anyway, because the
cells they enter come from E and start at ``r = 0``. So the default puts no mass on M, and
enough on O that after the first frame every cell seen occupied is O (the background is
learnt from the first frame, no empty room needed: ``0.99 * 0.4 > 0.1 * 0.6``), while a cell
that is not observed still ends up E after one prediction (``0.99 * 0.4 < 0.01 * 0.4 + 0.9
* 0.6``: unknown space counts as empty, not as an obstacle). A person present at frame 0 is
O where they stand at first and M wherever they move to: a walking person within the time
their body takes to clear its first position (about 10 frames at 1.3 m/s), a person who
stands still only once they move (only a waving arm is M until they start walking; the
built-in scenes, ``no_occlusion`` among them, start with their people already walking for
this reason). Putting most mass on E instead (``initial=(q, 0, 1 - q)``
with ``q`` small) makes everything seen occupied M for the first ``-ln(r_0) / ln(a)``
frames: the person then, but the whole room too, and from that frame on both choices give
the same states.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from occupose.camera import CAMERA_PRESETS, Camera, SensorSpec, matching_preset, pixels_from_points
from occupose.config import GridConfig
from occupose.grid import _kernels
from occupose.grid.spec import GridSpec
from occupose.sensors import NoiseEstimate, depth_std, depth_std_coefficients

#: Cell states (index into the last axis of ``OccupancyGrid.probabilities``).
O, M, E = 0, 1, 2
STATE_NAMES = ("O", "M", "E")
#: Cell visibility from the cameras.
UNOBSERVED, VISIBLE, HIDDEN = _kernels.UNOBSERVED, _kernels.VISIBLE, _kernels.HIDDEN

#: Defaults of the model's parameters: the fields of :class:`occupose.config.GridConfig`.
ALPHA, BETA, GAMMA, PSI = GridConfig.alpha, GridConfig.beta, GridConfig.gamma, GridConfig.psi
P_OCC, P_FREE = GridConfig.p_occ, GridConfig.p_free
TAIL_WIDTH = GridConfig.tail_width
INITIAL = GridConfig.initial
NO_RETURN = GridConfig.no_return
NO_RETURN_AFTER = GridConfig.no_return_after
#: Noise model for cameras whose intrinsics match no sensor preset (the noisier of the two).
DEFAULT_NOISE_MODEL = "structured_light"
#: Far range (metres) for cameras whose intrinsics match no sensor preset.
DEFAULT_MAX_RANGE = 4.5
#: Peak bytes per cell while a grid is made, whatever the number of cameras: the coverage
#: check's cell centres and their projections, freed before the grid's own arrays are made
#: (tracemalloc: 72.0 B on no_occlusion's grid at 0.4, 1.9 and 6.5 M cells and on
#: two_cameras_occlusion's at 0.7 and 3.3 M; docs/notes/2026-12-06-grid-projection-tables.md).
BYTES_PER_CELL = 72
#: Bytes per cell an :class:`OccupancyGrid` keeps: the (O, M, E) beliefs (3 float32), the
#: state, the visibility and the kernel's skip code (uint16).
GRID_BYTES_PER_CELL = 16
#: ... and per cell and camera: the cell centre's pixel (int32) and depth (float64).
TABLE_BYTES_PER_CELL = 12
#: Posterior probabilities below this are set to 0 (float32 never goes subnormal).
FLUSH = 1e-30
_LUT_STEP = 0.01
_NO_HOLD = np.zeros(0, np.bool_)
_LUT_DEPTH = 12.0


# ------------------------------------------------------------------------- the model


def observation_function(epsilon, half_extent, width, p_occ: float = P_OCC, p_free: float = P_FREE) -> np.ndarray:
    """The paper's Fig. 3: P(observation | cell occupied) as a function of epsilon = d - l.

    epsilon : (...) float, metres, measured depth minus the cell centre's depth (NaN: no
        measurement, or the cell is not in the image)
    half_extent : float or (...) float, metres, half the cell's extent along the optical axis
    width : float or (...) float, metres, the Gaussian tails' width (``tail_width`` times the
        sensor's depth noise at the cell's depth)
    Returns (...) float64 (module docstring): ``p_occ`` where |epsilon| <= half_extent, Gaussian
    tails down to ``p_free`` (epsilon > 0, seen through) and to 0.5 (epsilon < 0, hidden),
    exactly ``p_free`` / 0.5 beyond ``half_extent + 3 * width``, and 0.5 where epsilon is NaN.
    """
    epsilon, half_extent, width = np.broadcast_arrays(
        *(np.asarray(a, np.float64) for a in (epsilon, half_extent, width)))
    excess = np.abs(epsilon) - half_extent
    with np.errstate(invalid="ignore", divide="ignore"):
        tail = np.where(excess > _kernels.TAIL_CUT * width, 0.0,
                        np.exp(-0.5 * (np.maximum(excess, 0.0) / width) ** 2))
        tail = np.where(excess <= 0.0, 1.0, tail)
        far = np.where(epsilon > 0.0, p_free, 0.5)
        return np.where(np.isnan(epsilon), 0.5, far + (p_occ - far) * tail)


def transition_matrix(alpha: float = ALPHA, beta: float = BETA, gamma: float = GAMMA,
                      psi: float = PSI) -> np.ndarray:
    """(3, 3) float64 transition matrix A[previous, next] over states (O, M, E); see the module docstring."""
    for name, value in (("alpha", alpha), ("beta", beta), ("gamma", gamma), ("psi", psi)):
        if not (isinstance(value, (int, float, np.floating)) and 0.0 <= value <= 1.0):
            raise ValueError(f"{name} must be a probability in [0, 1], got {value!r}")
    if gamma + psi > 1.0:
        raise ValueError(f"gamma + psi must be <= 1 (they leave state M), got {gamma} + {psi}")
    return np.array([[1.0 - alpha, 0.0, alpha],
                     [psi, 1.0 - gamma - psi, gamma],
                     [0.0, beta, 1.0 - beta]])


def held_transition(transition: np.ndarray) -> np.ndarray:
    """(3, 3) float64: ``transition`` (A[previous, next] over O, M, E) without the M -> O
    transition, its M row renormalised (``A[M, M]`` and ``A[M, E]`` divided by ``1 - psi``):
    what cells held by the tracker use (:meth:`OccupancyGrid.update`)."""
    held = np.array(transition, np.float64)
    if held.shape != (3, 3) or not 0.0 <= held[M, O] < 1.0:
        raise ValueError(f"transition must be a (3, 3) matrix with A[M, O] = psi < 1, got {held.tolist()}")
    held[M] /= 1.0 - held[M, O]
    held[M, O] = 0.0
    return held


def frames_until_static(alpha: float = ALPHA, beta: float = BETA, gamma: float = GAMMA, psi: float = PSI,
                        p_occ: float = P_OCC) -> float:
    """Frames a cell entered from E and then seen occupied spends in M before it turns O.

    ``T = ln(1 + (gamma - alpha + psi - beta e) / psi) / ln((1 - alpha) / (1 - gamma - psi + beta e))``
    with ``e`` the settled E / M ratio (the module docstring derives it): 76.2 for the
    defaults. Returns inf when psi is 0 or when M outlasts O (``a <= 1``).
    """
    transition_matrix(alpha, beta, gamma, psi)
    if not 0.5 < p_occ <= 1.0:
        raise ValueError(f"p_occ must be in (0.5, 1], got {p_occ!r}")
    k = (1.0 - p_occ) / p_occ
    linear = 1.0 - gamma - psi - k * (1.0 - beta)
    if beta > 0.0:
        e = (-linear + math.sqrt(linear * linear + 4.0 * beta * k * gamma)) / (2.0 * beta)
    else:
        e = k * gamma / linear if linear > 0.0 else math.inf
    stay = 1.0 - gamma - psi + beta * e
    if psi == 0.0 or not (stay < 1.0 - alpha):
        return math.inf
    if stay == 0.0:
        return 0.0
    return math.log1p((gamma - alpha + psi - beta * e) / psi) / math.log((1.0 - alpha) / stay)


# ------------------------------------------------------------------------- geometry


def _preset_of(camera: Camera) -> SensorSpec | None:
    """The sensor preset the camera is (:func:`occupose.camera.matching_preset`), if any."""
    name = matching_preset(camera)
    return None if name is None else CAMERA_PRESETS[name]


def _check_cameras(cameras) -> tuple[Camera, ...]:
    cameras = tuple(cameras) if not isinstance(cameras, Camera) else (cameras,)
    if not cameras or not all(isinstance(c, Camera) for c in cameras):
        raise ValueError(f"cameras must be a non-empty sequence of occupose.camera.Camera, got {cameras!r}")
    names = [c.name for c in cameras]
    if len(set(names)) != len(names):
        raise ValueError(f"camera names must be unique, got {names}")
    return cameras


def _max_ranges(cameras: tuple[Camera, ...], max_range) -> dict[str, float]:
    """Far range per camera: given (float or name -> float), else the sensor preset's, else DEFAULT_MAX_RANGE."""
    out = {}
    for cam in cameras:
        if max_range is None:
            preset = _preset_of(cam)
            value = preset.far if preset is not None else DEFAULT_MAX_RANGE
        elif isinstance(max_range, Mapping):
            if cam.name not in max_range:
                raise ValueError(f"max_range has no entry for camera {cam.name!r} (it has {sorted(max_range)})")
            value = max_range[cam.name]
        else:
            value = max_range
        if not (isinstance(value, (int, float, np.floating)) and math.isfinite(value) and value > 0):
            raise ValueError(f"max_range for camera {cam.name!r} must be a positive number of metres, got {value!r}")
        out[cam.name] = float(value)
    return out


def view_pyramid(camera: Camera, far: float) -> tuple[np.ndarray, list[tuple[int, int]]]:
    """The camera's view pyramid up to depth ``far`` (metres): (5, 3) world vertices,
    metres (the camera's centre first, then the image corners' rays at depth ``far``),
    and its 8 edges as pairs of vertex indices."""
    corners = np.array([[-0.5, -0.5], [camera.width - 0.5, -0.5],
                        [camera.width - 0.5, camera.height - 0.5], [-0.5, camera.height - 0.5]])
    local = np.column_stack([(corners[:, 0] - camera.cx) / camera.fx * far,
                             (corners[:, 1] - camera.cy) / camera.fy * far, np.full(4, far)])
    pose = camera.world_from_camera
    vertices = np.vstack([pose[:3, 3], local @ pose[:3, :3].T + pose[:3, 3]])
    edges = [(0, 1), (0, 2), (0, 3), (0, 4), (1, 2), (2, 3), (3, 4), (4, 1)]
    return vertices, edges


def _frustum_in_slab(camera: Camera, far: float, z_low: float, z_high: float) -> np.ndarray:
    """(K, 3) vertices of the view pyramid clipped to z_low <= z <= z_high (K = 0: no overlap).

    A vertex of the clipped pyramid is either a pyramid vertex inside the slab or where a
    pyramid edge crosses one of the two planes, so their bounding box is exact.
    """
    vertices, edges = view_pyramid(camera, far)
    inside = (vertices[:, 2] >= z_low) & (vertices[:, 2] <= z_high)
    points = [vertices[inside]]
    for a, b in edges:
        za, zb = vertices[a, 2], vertices[b, 2]
        for plane in (z_low, z_high):
            if za != zb and min(za, zb) <= plane <= max(za, zb):
                s = (plane - za) / (zb - za)
                point = vertices[a] + s * (vertices[b] - vertices[a])
                point[2] = plane
                points.append(point[None])
    return np.vstack(points)


def _cells_seen(spec: GridSpec, camera: Camera, far: float) -> int:
    """Number of cell centres that project into the camera's image at a depth in (0, far]."""
    uv, z = pixels_from_points(spec.centers().reshape(-1, 3), camera)
    u, v = np.floor(uv[:, 0] + 0.5), np.floor(uv[:, 1] + 0.5)
    with np.errstate(invalid="ignore"):
        seen = (z > 0) & (z <= far) & (u >= 0) & (u < camera.width) & (v >= 0) & (v < camera.height)
    return int(np.count_nonzero(seen))


def _check_coverage(spec: GridSpec, cameras: tuple[Camera, ...], far: dict[str, float]) -> None:
    for cam in cameras:
        if _cells_seen(spec, cam, far[cam.name]) == 0:
            raise ValueError(
                f"camera {cam.name!r} sees no cell of the grid box {list(spec.origin)} - {spec.high.tolist()} "
                f"within {far[cam.name]:g} m (camera outside the grid, or looking away from it)"
            )


def spec_from_cameras(cameras: Sequence[Camera], cell: float = 0.05, height: float = 2.2,
                      max_range=None, bounds=None, max_cells: int | None = None) -> GridSpec:
    """The grid over what the cameras see, between the floor and ``height``.

    cameras : Camera or sequence of Camera
    cell : float, metres, cell edge
    height : float, metres, top of the grid (the floor z = 0 is the bottom)
    max_range : None (each camera's sensor preset far range when its intrinsics match a
        preset, else DEFAULT_MAX_RANGE), a float or a dict camera name -> float, metres:
        how far along its optical axis each camera's view is kept
    bounds : None, or (low (3,), high (3,)) metres, an explicit grid box (then ``height``
        is not used)
    max_cells : None, or the most cells the grid may have (``limits.grid_cells``): a larger
        grid is refused before anything is allocated, with its size and memory
        (:func:`bytes_per_cell` of the number of cameras)
    Returns the GridSpec covering the bounding box of the cameras' view pyramids clipped
    to 0 <= z <= height (or ``bounds``), extended down to z = -cell / 2 so that the bottom
    layer of cells is centred on the floor: the cell centres' rays then meet the floor
    inside those cells, whereas a floor lying on the boundary between two layers reads as
    seen through at grazing angles (the ray through a centre above it leaves the cell
    before it reaches the floor). Raises ValueError for an empty box and for a camera
    that sees none of it.
    """
    cameras = _check_cameras(cameras)
    if not (isinstance(cell, (int, float, np.floating)) and math.isfinite(cell) and cell > 0):
        raise ValueError(f"cell must be a positive number of metres, got {cell!r}")
    far = _max_ranges(cameras, max_range)
    if bounds is not None:
        low, high = (np.asarray(b, np.float64) for b in bounds)
        _check_size(low, high, cell, max_cells, len(cameras))
        spec = GridSpec.from_bounds(low, high, cell)
    else:
        if not (isinstance(height, (int, float, np.floating)) and math.isfinite(height) and height > 0):
            raise ValueError(f"height must be a positive number of metres (the grid spans z = 0 .. height), "
                             f"got {height!r}")
        clipped = []
        for cam in cameras:
            points = _frustum_in_slab(cam, far[cam.name], 0.0, float(height))
            if len(points) == 0:
                raise ValueError(f"camera {cam.name!r} sees nothing between the floor and z = {height:g} m "
                                 f"within {far[cam.name]:g} m (camera outside the grid, or looking away from it)")
            clipped.append(points)
        points = np.vstack(clipped)
        low = points.min(axis=0)
        low[2] = -0.5 * cell  # the bottom layer is centred on the floor
        high = points.max(axis=0)
        _check_size(low, high, cell, max_cells, len(cameras))
        spec = GridSpec.from_bounds(low, high, cell)
    _check_coverage(spec, cameras, far)
    return spec


def bytes_per_cell(num_cameras: int) -> int:
    """Peak bytes per cell of making and updating a grid seen by ``num_cameras`` cameras:
    the larger of the coverage check's :data:`BYTES_PER_CELL` and what the grid keeps,
    :data:`GRID_BYTES_PER_CELL` + :data:`TABLE_BYTES_PER_CELL` per camera (72 B up to four
    cameras, 76 B for five; each camera's image adds 4 bytes a pixel)."""
    return max(BYTES_PER_CELL, GRID_BYTES_PER_CELL + TABLE_BYTES_PER_CELL * int(num_cameras))


def _check_size(low: np.ndarray, high: np.ndarray, cell: float, max_cells: int | None, num_cameras: int) -> None:
    """ValueError with the grid's size and memory (:func:`bytes_per_cell`) when the box from
    ``low`` to ``high`` (metres) holds more than ``max_cells`` cells of ``cell`` metres
    (counted in floats: no overflow, nothing allocated)."""
    counts = np.ceil((np.asarray(high) - np.asarray(low)) / cell - 1e-9)
    cells = float(np.prod(counts))
    if max_cells is not None and cells > max_cells:
        per_cell = bytes_per_cell(num_cameras)
        raise ValueError(f"grid.cell = {cell:g} m gives a grid of {' x '.join(f'{c:.0f}' for c in counts)} = "
                         f"{cells:.3g} cells over the cameras' view "
                         f"({' x '.join(f'{v:.3g}' for v in np.asarray(high) - low)} m), about "
                         f"{cells * per_cell / 1e9:.3g} GB; the bound limits.grid_cells is {max_cells:,} cells "
                         f"(about {max_cells * per_cell / 1e9:.2g} GB): use a larger grid.cell, or a shorter "
                         f"grid.max_range or grid.height")


def _check_states(states: np.ndarray, spec: GridSpec) -> np.ndarray:
    states = np.asarray(states)
    if states.shape != spec.shape or states.dtype != np.uint8:
        raise ValueError(f"states must be a uint8 {spec.shape} array of cell states, got {states.dtype} {states.shape}")
    return states


def cells_from_depth(depth: np.ndarray, camera: Camera, spec: GridSpec, states: np.ndarray | None = None, *,
                     labels: np.ndarray | None = None, claims: np.ndarray | None = None,
                     within: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """The grid cell of every depth pixel's back-projected 3D point (the paper's Fig. 2(d)).

    depth : (H, W) float metres or uint16 raw, H, W = camera.height, camera.width (0 = no measurement)
    states : optional (nx, ny, nz) uint8 cell states. A measured point inside a cell the
        grid holds empty lies on an object's silhouette edge: the ray through the cell's
        centre passes beside the object, so the cell reads as seen through although the
        object covers part of it. With ``states``, such a point is given to the nearest
        (by centre distance) O or M cell among the 26 around its own, if there is one.
    labels : optional (nx, ny, nz) int32 cell labels (`blobs_from_mask`), with ``claims``
        (L,) int64 indexed by label, L > labels.max(): only the points whose cell's label
        has a nonzero claim keep their cell (the others get -1).
    within : optional ((3,), (3,)) int, the lowest and highest cell index (i, j, k) looked
        at: a point whose own cell lies outside gets -1 (neither moved nor labelled).
    Returns (H, W) int64: flat cell index ``(i * ny + j) * nz + k`` into ``spec.shape``, -1
    where there is no measurement, the point is outside the grid (or ``within``) or its label
    is not claimed.
    """
    depth = np.asarray(depth)
    if depth.shape != (camera.height, camera.width):
        raise ValueError(f"depth image for camera {camera.name!r} must have shape ({camera.height}, {camera.width}), "
                         f"got {depth.shape}")
    if depth.dtype == np.uint16:
        depth = (depth * camera.depth_scale).astype(np.float32)
    elif depth.dtype.kind != "f":
        raise ValueError(
            f"depth image for camera {camera.name!r} must be float metres or uint16 raw, got {depth.dtype}")
    states = np.zeros(0, np.uint8) if states is None else _check_states(states, spec).reshape(-1)
    if (labels is None) != (claims is None):
        raise ValueError("labels and claims go together: give both or neither")
    if labels is None:
        labels, claims = np.zeros(0, np.int32), np.zeros(0, np.int64)
    else:
        labels, claims = np.asarray(labels), np.asarray(claims)
        if labels.shape != spec.shape or labels.dtype != np.int32:
            raise ValueError(f"labels must be an int32 {spec.shape} array, got {labels.dtype} {labels.shape}")
        if claims.ndim != 1 or claims.dtype != np.int64 or claims.size <= max(int(labels.max(initial=0)), 0):
            raise ValueError(f"claims must be an int64 array over every label (more than {labels.max(initial=0)}), "
                             f"got {claims.dtype} {claims.shape}")
        labels = np.ascontiguousarray(labels).reshape(-1)
    bounds = np.array([[0, 0, 0], np.subtract(spec.shape, 1)], np.int64)
    if within is not None:
        bounds = np.array(within, np.int64).reshape(2, 3)
    out = np.empty(camera.height * camera.width, np.int64)
    pose = camera.world_from_camera
    _kernels.cells_from_pixels(np.ascontiguousarray(depth, np.float32), camera.fx, camera.fy, camera.cx, camera.cy,
                               np.ascontiguousarray(pose[:3, :3]), pose[:3, 3].copy(), np.asarray(spec.origin),
                               spec.cell, *spec.shape, np.clip(bounds, 0, np.subtract(spec.shape, 1)), states, labels,
                               claims, out)
    return out.reshape(camera.height, camera.width)


# ------------------------------------------------------------------------- the grid


class OccupancyGrid:
    """The per-cell HMM and visibility of a grid seen by depth cameras, frame after frame.

    spec : GridSpec (see :func:`spec_from_cameras`)
    cameras : Camera or sequence of Camera (unique names)
    noise_models : None or dict camera name -> noise model name of :mod:`occupose.sensors`
        (``"structured_light"``, ``"tof"``, ``"none"``) or a measured
        :class:`occupose.sensors.NoiseEstimate`: sets each camera's depth tolerance.
        Default: the camera's sensor preset's model when its intrinsics match a preset
        (:func:`occupose.camera.matching_preset`), else DEFAULT_NOISE_MODEL.
    alpha, beta, gamma, psi : transition probabilities (module docstring)
    p_occ, p_free : the observation function's levels; tail_width : width of its tails in
        sensor depth standard deviations (module docstring)
    initial : (3,) initial distribution over (O, M, E), summing to 1 (module docstring)
    max_range : as in :func:`spec_from_cameras`: each camera's far range (metres), where a
        pixel that measured nothing is evidence against O in the cells in front of it, and
        used to check each camera sees part of the grid
    no_return : factor (0, 1] on O's likelihood in front of such a pixel (module docstring)
    no_return_after : frames in a row (>= 1) a pixel must have measured nothing before it
        counts as no return (module docstring)

    After :meth:`update`: ``states`` (nx, ny, nz) uint8 MAP state (O, M, E),
    ``probabilities`` (nx, ny, nz, 3) float32 posterior over (O, M, E), ``visibility``
    (nx, ny, nz) uint8 (VISIBLE, HIDDEN, UNOBSERVED), ``num_updates`` frames seen,
    ``stepped`` the cells whose HMM step ran in the last update (the others would not change).
    """

    def __init__(self, spec: GridSpec, cameras, noise_models: Mapping[str, str | NoiseEstimate] | None = None, *,
                 alpha: float = ALPHA, beta: float = BETA, gamma: float = GAMMA, psi: float = PSI,
                 p_occ: float = P_OCC, p_free: float = P_FREE, tail_width: float = TAIL_WIDTH,
                 initial=INITIAL, max_range=None, no_return: float = NO_RETURN,
                 no_return_after: int = NO_RETURN_AFTER):
        if not isinstance(spec, GridSpec):
            raise ValueError(f"spec must be a GridSpec, got {type(spec).__name__}")
        self.spec = spec
        self.cameras = _check_cameras(cameras)
        self.transition = transition_matrix(alpha, beta, gamma, psi)
        #: (3, 3) the transition matrix of held cells (:meth:`update`): psi = 0, the M row renormalised.
        self.held_transition = held_transition(self.transition)
        self.alpha, self.beta, self.gamma, self.psi = float(alpha), float(beta), float(gamma), float(psi)
        if not (0.5 < p_occ <= 1.0 and 0.0 <= p_free < 0.5):
            raise ValueError(f"need 0.5 < p_occ <= 1 and 0 <= p_free < 0.5, got p_occ={p_occ!r}, p_free={p_free!r}")
        if not (math.isfinite(tail_width) and tail_width >= 0):
            raise ValueError(f"tail_width must be a number >= 0, got {tail_width!r}")
        self.p_occ, self.p_free, self.tail_width = float(p_occ), float(p_free), float(tail_width)
        if not (0.0 < no_return <= 1.0):
            raise ValueError(f"no_return must be in (0, 1], got {no_return!r}")
        self.no_return = float(no_return)
        if isinstance(no_return_after, bool) or not isinstance(no_return_after, (int, np.integer)) \
                or not 1 <= no_return_after < np.iinfo(np.uint16).max:
            raise ValueError(f"no_return_after must be a whole number of frames in [1, 65534], got {no_return_after!r}")
        self.no_return_after = int(no_return_after)
        initial = np.asarray(initial, np.float64)
        if initial.shape != (3,) or np.any(initial < 0) or abs(initial.sum() - 1.0) > 1e-6:
            raise ValueError(f"initial must be 3 probabilities for (O, M, E) summing to 1, got {initial.tolist()}")
        self.initial = initial
        names = [c.name for c in self.cameras]
        if noise_models is None:
            noise_models = {}
        elif not isinstance(noise_models, Mapping) or set(noise_models) - set(names):
            raise ValueError(f"noise_models must be a dict camera name -> noise model name or NoiseEstimate for "
                             f"cameras {names}, got {noise_models!r}")
        self.noise_models = {}
        for cam in self.cameras:
            preset = _preset_of(cam)
            model = noise_models.get(cam.name, preset.noise if preset is not None else DEFAULT_NOISE_MODEL)
            if not isinstance(model, NoiseEstimate):
                depth_std_coefficients(model)  # raises with the valid names
            self.noise_models[cam.name] = model
        #: camera name -> its far range, metres along its optical axis
        self.max_ranges = _max_ranges(self.cameras, max_range)
        _check_coverage(spec, self.cameras, self.max_ranges)
        self._fars = np.array([self.max_ranges[cam.name] for cam in self.cameras], np.float64)
        self._camera_arrays()
        self._probabilities = np.empty(spec.shape + (3,), np.float32)
        self._probabilities[...] = initial
        self._states = np.full(spec.shape, int(np.argmax(initial)), np.uint8)
        self._visibility = np.zeros(spec.shape, np.uint8)
        self._quiet = np.zeros(spec.num_cells, np.uint16)  # the kernel's skip codes (occupose.grid._kernels)
        self.num_updates = 0
        self.stepped = 0

    def _camera_arrays(self) -> None:
        """Per-camera arrays of the kernel, and where every cell centre falls in every image
        (module docstring of occupose.grid._kernels): the cameras do not move, so each cell's
        pixel and depth are found once, here."""
        count = len(self.cameras)
        rotations = np.empty((count, 3, 3))
        translations = np.empty((count, 3))
        intrinsics = np.empty((count, 4))
        sizes = np.empty((count, 2), np.int64)
        self._offsets = np.zeros(count, np.int64)
        self._half_extents = np.empty(count)
        lut_depths = np.arange(int(round(_LUT_DEPTH / _LUT_STEP)) + 1) * _LUT_STEP
        self._sigma_lut = np.empty((count, lut_depths.size))
        offset = 0
        for c, cam in enumerate(self.cameras):
            pose = cam.camera_from_world
            rotations[c] = pose[:3, :3]
            translations[c] = pose[:3, 3]
            intrinsics[c] = (cam.fx, cam.fy, cam.cx, cam.cy)
            sizes[c] = (cam.width, cam.height)
            self._offsets[c] = offset
            offset += cam.width * cam.height
            self._half_extents[c] = 0.5 * self.spec.cell * np.abs(pose[2, :3]).sum()
            model = self.noise_models[cam.name]
            measured = isinstance(model, NoiseEstimate)
            self._sigma_lut[c] = model.std(lut_depths) if measured else depth_std(lut_depths, model)
        self._depth = np.empty(offset, np.float32)
        #: (sum H*W,) frames in a row each pixel has measured nothing, at most no_return_after,
        #: and the pixels where it has reached no_return_after (returnless, :meth:`update`)
        self._missing_run = np.zeros(offset, np.uint16)
        self._returnless = np.zeros(offset, np.bool_)
        num_cells = self.spec.num_cells
        #: (N, C) each cell centre's flat pixel index in each image (-1: none) and its depth
        #: along the optical axis (metres); the tail width there is looked up from it
        #: (_kernels.tail_width_at)
        self._pixels = np.empty((num_cells, count), np.int32)
        self._depths_l = np.empty((num_cells, count))
        _kernels.pixels_from_cells(np.asarray(self.spec.origin), self.spec.cell, *self.spec.shape, rotations,
                                   translations, intrinsics, sizes, self._pixels, self._depths_l)

    def depth_noise(self, depth_l, camera: str) -> np.ndarray:
        """The depth noise (one standard deviation, metres) the grid assumes for camera ``camera``
        at depth ``depth_l`` ((...) float, metres), as tabulated in 1 cm steps."""
        c = self._camera_index(camera)
        m = (np.asarray(depth_l, np.float64) * (1.0 / _LUT_STEP)).astype(np.int64)
        m = np.minimum(m, self._sigma_lut.shape[1] - 1)
        return self._sigma_lut[c, m]

    def half_extent(self, camera: str) -> float:
        """Half a cell's extent (metres) along camera ``camera``'s optical axis."""
        return float(self._half_extents[self._camera_index(camera)])

    def _camera_index(self, camera: str) -> int:
        names = [cam.name for cam in self.cameras]
        if camera not in names:
            raise ValueError(f"unknown camera {camera!r}; the grid's cameras are {names}")
        return names.index(camera)

    def _check_depths(self, depths: Mapping[str, np.ndarray]) -> None:
        names = [c.name for c in self.cameras]
        if not isinstance(depths, Mapping) or set(depths) != set(names):
            got = sorted(depths) if isinstance(depths, Mapping) else type(depths).__name__
            raise ValueError(f"depths must be a dict with one image per camera {names}, got {got}")
        for c, cam in enumerate(self.cameras):
            image = np.asarray(depths[cam.name])
            if image.shape != (cam.height, cam.width):
                raise ValueError(f"depth image for camera {cam.name!r} must have shape ({cam.height}, {cam.width}), "
                                 f"got {image.shape}")
            if image.dtype not in (np.float32, np.float64):
                raise ValueError(f"depth image for camera {cam.name!r} must be float32 metres, got {image.dtype} "
                                 f"(raw uint16 depth: multiply by camera.depth_scale)")
            start = self._offsets[c]
            self._depth[start:start + image.size] = image.reshape(-1)

    def update(self, depths: Mapping[str, np.ndarray], hold: np.ndarray | None = None) -> None:
        """Take one frame: depths is a dict camera name -> (H, W) float32 metres (0 = no measurement).

        hold : None, or (nx, ny, nz) bool: cells the tracker holds as moving in this frame
            (see :func:`occupose.grid.hold.cells_near_capsules`), so that a person it follows
            stays M while standing or sitting still. In a held cell the M -> O transition is
            disabled (``psi = 0``: the M row renormalised, :attr:`held_transition`), and a
            held cell whose MAP state is M first moves its O share to M. Both are needed:
            O and M look alike, so a cell's O share grows by the factor ``a`` (1.63 by
            default, module docstring) every frame it is seen occupied whatever psi is, and
            even the tiny share left from the initial distribution or from a few unheld
            frames (about 1e-26 in a cell seen through for 20 frames before a person stepped
            in) makes it O: with psi = 0 alone, a box walking in from the first frame and
            held all along turned static 120 frames after it stopped instead of 77
            (the construction of tests/grid/test_hold.py). Moving the share keeps it at 0. Held cells in O or E step as with psi = 0 only, so the hold takes nothing from
            the background (the floor under the feet, the seat of a chair stay O) and makes
            no cell occupied. A bool mask is what the kernel reads cheapest: one byte per
            cell in its parallel loop.

        Runs one fused numba kernel over all cells (it releases the GIL, so another thread
        can work meanwhile); it reads each cell centre's pixel and depth per camera from
        tables made with the grid (12 bytes per cell and camera), and the tail width there
        from the noise table. A cell's HMM step is skipped where it would change nothing: the
        cell is not held, its last step left its probabilities bit for bit as they were, and
        every camera observes it as then with the same value of the observation function
        (seen through beyond the tails, on the surface, hidden beyond the tails, or not
        measured). The step is a function of these alone, so the beliefs, states and
        visibility are exactly those of stepping every cell; most of the background is such
        cells once it has settled (``stepped``: the cells stepped in the last update).
        """
        self._check_depths(depths)
        if hold is None:
            hold = _NO_HOLD
        else:
            hold = np.asarray(hold)
            if hold.shape != self.spec.shape or hold.dtype != np.bool_:
                raise ValueError(f"hold must be a bool array of the grid's shape {self.spec.shape}, "
                                 f"got {hold.dtype} {hold.shape}")
            hold = np.ascontiguousarray(hold).reshape(-1)
        if self.no_return < 1.0:
            _kernels.count_missing(self._depth, self._missing_run, self.no_return_after, self._returnless)
        self.stepped = _kernels.update_grid(
            self.spec.shape[0], self._pixels, self._depths_l, self._sigma_lut, _LUT_STEP, self.tail_width,
            self._offsets, self._depth,
            self._returnless, self._half_extents, self._fars, self.p_occ, self.p_free, self.no_return, self.transition,
            self.held_transition, hold, FLUSH,
            self._probabilities.reshape(-1, 3), self._states.reshape(-1), self._visibility.reshape(-1), self._quiet,
        )
        self.num_updates += 1

    def returnless(self, camera: str) -> np.ndarray:
        """(H, W) bool copy: the pixels of camera ``camera`` that have measured nothing for
        ``no_return_after`` frames in a row, as of the last :meth:`update` (all False with
        ``no_return`` 1, where they are not counted)."""
        c = self._camera_index(camera)
        cam = self.cameras[c]
        start = self._offsets[c]
        return self._returnless[start:start + cam.width * cam.height].reshape(cam.height, cam.width).copy()

    @property
    def states(self) -> np.ndarray:
        """(nx, ny, nz) uint8 MAP state per cell: O, M or E (read-only view)."""
        view = self._states.view()
        view.flags.writeable = False
        return view

    @property
    def probabilities(self) -> np.ndarray:
        """(nx, ny, nz, 3) float32 posterior over (O, M, E) per cell (read-only view)."""
        view = self._probabilities.view()
        view.flags.writeable = False
        return view

    @property
    def visibility(self) -> np.ndarray:
        """(nx, ny, nz) uint8 per cell in the last frame: VISIBLE (in front of or on the measured
        surface for some camera), HIDDEN (behind it for every camera that measures it), UNOBSERVED
        (no camera measures its pixel). Read-only view; all UNOBSERVED before the first update."""
        view = self._visibility.view()
        view.flags.writeable = False
        return view

    def moving_mask(self) -> np.ndarray:
        """(nx, ny, nz) bool: cells whose MAP state is M."""
        return self._states == M

    def seed_moving(self, cells: np.ndarray) -> None:
        """Set the cells of ``cells`` ((nx, ny, nz) bool) to M with certainty: something the
        grid took for background is known to be a person (a person standing still from the
        first frame, :func:`occupose.pose.start.still_people`). Such a cell is then as one just
        entered from E: seen occupied, it turns O after :func:`frames_until_static` frames
        (77 by default) unless it is held (the tracker holds the people it tracks), and it
        becomes E when it is seen through."""
        cells = np.asarray(cells)
        if cells.shape != self.spec.shape or cells.dtype != np.bool_:
            raise ValueError(f"cells must be a bool array of the grid's shape {self.spec.shape}, "
                             f"got {cells.dtype} {cells.shape}")
        self._probabilities[cells] = (0.0, 1.0, 0.0)
        self._states[cells] = M
        self._quiet[cells.reshape(-1)] = 0

    def visibility_at(self, points: np.ndarray) -> np.ndarray:
        """Visibility of the cells containing world points.

        points : (N, 3) float, metres, world frame
        Returns (N,) uint8: VISIBLE, HIDDEN or UNOBSERVED (also for points outside the grid).
        """
        points = np.asarray(points, np.float64)
        if points.ndim != 2 or points.shape[1] != 3:
            raise ValueError(f"points must have shape (N, 3), got {points.shape}")
        index, inside = self.spec.cells_from_points(points)
        out = self._visibility[index[:, 0], index[:, 1], index[:, 2]]
        return np.where(inside, out, UNOBSERVED).astype(np.uint8)
