"""A run's frame rate and cameras checked against ``config.limits`` before any work.

A setting or a camera that would make a run take unbounded time or memory, or track
nothing because the camera cannot see the room, is refused here with a ValueError that
says what it would cost or what was seen, instead of a hang, a MemoryError after minutes
or an empty result reported as success (issue 26). The size of the occupancy grid is
checked where it is made (:func:`occupose.grid.occupancy.spec_from_cameras`, ``max_cells``).

Before the first frame (:func:`check_fps`, :func:`check_cameras`, :func:`check_reach`):
the frame rate, each camera's image size, how far its rays reach from the optical axis
(a principal point far outside the image or a tiny focal length), its distance from the
world origin, that it is above the floor, and that its view within its far range comes
down near the floor. On each camera's first frame with measurements
(:func:`check_first_view`): that some of them lie within its far range, and that not most
of those lie below the floor (a wrong pose or depth scale).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from occupose._validate import positive_float
from occupose.camera import Camera, points_from_depth
from occupose.config import LimitsConfig
from occupose.grid.occupancy import view_pyramid


def check_fps(fps, limits: LimitsConfig) -> float:
    """``fps`` (frames per second) as a float within ``limits.min_fps .. limits.max_fps``."""
    fps = positive_float(fps, "fps")
    if not limits.min_fps <= fps <= limits.max_fps:
        raise ValueError(f"fps = {fps:g} frames/s is outside the frame rates tracked, {limits.min_fps:g} .. "
                         f"{limits.max_fps:g} (limits.min_fps, limits.max_fps)")
    return fps


def ray_angle_deg(camera: Camera) -> float:
    """The largest angle (degrees) between the optical axis and the ray of an image corner."""
    u = np.array([-0.5, camera.width - 0.5]) - camera.cx
    v = np.array([-0.5, camera.height - 0.5]) - camera.cy
    tangent = math.hypot(np.abs(u / camera.fx).max(), np.abs(v / camera.fy).max())
    return math.degrees(math.atan(tangent))


def check_cameras(cameras: Sequence[Camera], limits: LimitsConfig) -> None:
    """Each camera's image size, ray angle, distance from the origin and height above the floor."""
    if not cameras or not all(isinstance(c, Camera) for c in cameras):
        raise TypeError(f"cameras must be a non-empty sequence of occupose.camera.Camera, got {cameras!r}")
    for cam in cameras:
        pixels = cam.width * cam.height
        if pixels > limits.image_pixels:
            raise ValueError(f"camera {cam.name!r}: its {cam.width} x {cam.height} image has {pixels:,} pixels, "
                             f"{4 * pixels / 1e9:.3g} GB a depth frame as float32; the bound limits.image_pixels "
                             f"is {limits.image_pixels:,}")
        angle = ray_angle_deg(cam)
        if angle > limits.ray_angle_deg:
            raise ValueError(f"camera {cam.name!r}: fx = {cam.fx:g}, fy = {cam.fy:g}, cx = {cam.cx:g}, cy = "
                             f"{cam.cy:g} for a {cam.width} x {cam.height} image put its corner rays "
                             f"{angle:.1f} deg from the optical axis; a pinhole camera's stay within "
                             f"{limits.ray_angle_deg:g} deg (limits.ray_angle_deg): is the principal point "
                             f"inside the image, the focal length in pixels?")
        position = cam.position
        distance = float(np.linalg.norm(position))
        if distance > limits.distance_m:
            raise ValueError(f"camera {cam.name!r} is {distance:.3g} m from the world origin; the bound "
                             f"limits.distance_m is {limits.distance_m:g} m (world_from_camera's translation "
                             f"is in metres, the origin in the room)")
        if position[2] <= 0.0:
            raise ValueError(f"camera {cam.name!r} is at z = {position[2]:.3g} m, not above the floor: "
                             f"world_from_camera must have z up and the floor at z = 0")


def check_reach(cameras: Sequence[Camera], far: Mapping[str, float], limits: LimitsConfig) -> None:
    """Each camera's view pyramid up to its far range ``far[name]`` (metres) comes down to
    ``limits.lowest_view_m`` above the floor."""
    for cam in cameras:
        lowest = float(view_pyramid(cam, far[cam.name])[0][:, 2].min())
        if lowest > limits.lowest_view_m:
            down = math.degrees(cam.down_angle)
            raise ValueError(f"camera {cam.name!r} sees nothing below z = {lowest:.2f} m within its far range of "
                             f"{far[cam.name]:g} m (its optical axis {abs(down):.0f} deg "
                             f"{'below' if down >= 0 else 'above'} the horizontal): it cannot see the floor or "
                             f"anyone's legs; is world_from_camera inverted? (bound: limits.lowest_view_m = "
                             f"{limits.lowest_view_m:g} m)")


def check_first_view(camera: Camera, depth: np.ndarray, far: float, limits: LimitsConfig) -> bool:
    """Check one camera's first frame: ``depth`` (H, W) float32 metres (0: no measurement),
    ``far`` its far range, metres. Returns False when the frame has no measurement (check
    the next one), True when it passed; raises ValueError when nothing measured is within
    ``far``, or when more than ``limits.below_floor_share`` of it lies more than
    ``limits.floor_margin`` below the floor."""
    points, _ = points_from_depth(depth, camera, frame="camera")
    if len(points) == 0:
        return False
    near = points[points[:, 2] <= far]
    if len(near) == 0:
        raise ValueError(f"camera {camera.name!r} sees nothing within its far range of {far:g} m: of its "
                         f"{len(points):,} measured pixels the nearest is at {points[:, 2].min():.3g} m (is its "
                         f"depth_scale, {camera.depth_scale:g} m per unit, right?)")
    heights = near @ camera.world_from_camera[2, :3] + camera.world_from_camera[2, 3]
    below = float(np.mean(heights < -limits.floor_margin))
    if below > limits.below_floor_share:
        raise ValueError(f"camera {camera.name!r}: {100 * below:.0f} % of what it sees within {far:g} m lies more "
                         f"than {limits.floor_margin:g} m below the floor (down to z = {heights.min():.2f} m); "
                         f"its world_from_camera or depth_scale is wrong (bound: limits.below_floor_share = "
                         f"{limits.below_floor_share:g})")
    return True
