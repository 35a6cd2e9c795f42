"""Videos of recordings: every frame of one camera, depth colour-mapped, the tracked
skeletons drawn over it, encoded as MP4 with PyAV (extra ``kinect``; docs/outputs.md).

:func:`frame_image` draws one frame (arrays in, an RGB array out); :func:`write_video`
writes a whole recording, whole or not at all (:func:`occupose.io.output.staged_file`).
Drawing is done with Pillow's ImageDraw on the colour-mapped depth: bones between joints
estimated from data are solid lines, bones to a hidden joint (carried from memory)
dashed; visible joints are dots, hidden ones crosses; each track in its colour
(:func:`occupose.viz.track_color`), outlined in black, its id beside its head.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterable, Mapping
from fractions import Fraction
from functools import lru_cache
from pathlib import Path

import numpy as np

from occupose.camera import Camera, pixels_from_points
from occupose.io.output import SOFTWARE, OutputError, staged_file
from occupose.io.writers import tracks_from_table
from occupose.joints import BONES, JOINT_INDEX
from occupose.viz import DEPTH_COLORMAP, depth_range, track_color

#: The file suffix of videos.
VIDEO_SUFFIX = ".mp4"
#: Encoders in order of preference, each with its options: H.264 (libx264, constant
#: quality CRF 18, near transparent) where the FFmpeg inside PyAV has it, else MPEG-4 part 2.
ENCODERS: tuple[tuple[str, dict[str, str]], ...] = (
    ("libx264", {"crf": "18", "preset": "medium"}),
    ("mpeg4", {}),
)
#: Bits per pixel and frame of the MPEG-4 fallback (it takes a bit rate, not a quality):
#: 0.25 is about 2.3 Mbit/s for 640 x 480 at 30 frames/s.
MPEG4_BITS_PER_PIXEL = 0.25
#: Pixel format of the video: 4:2:0 YUV, which every player decodes (width and height even).
PIXEL_FORMAT = "yuv420p"
#: A non-integer frame rate is written as the nearest fraction with at most this
#: denominator (29.97 = 2997/100, 30000/1001 exactly).
FPS_MAX_DENOMINATOR = 1001
#: The MP4 ``comment`` tag of every video occupose writes: how --force tells one of ours.
VIDEO_COMMENT = SOFTWARE

#: Sizes of the drawing, pixels, for an image STYLE_HEIGHT_PX rows high; a taller image
#: scales them up (a smaller one keeps them).
STYLE_HEIGHT_PX = 480
LINE_WIDTH_PX = 2
OUTLINE_PX = 1  # the black border around every line, dot, cross and text
JOINT_RADIUS_PX = 3
CROSS_HALF_PX = 4  # half the side of a hidden joint's cross
DASH_PX = 5  # the dashes of a bone to a hidden joint: DASH_PX drawn, DASH_PX left out
TEXT_HEIGHT_PX = 14
TEXT_MARGIN_PX = 4
OUTLINE_COLOR = (0, 0, 0)
TEXT_COLOR = (255, 255, 255)
#: Depth pixels without a measurement.
NO_DEPTH_COLOR = (0, 0, 0)
#: Entries of the colormap lookup table.
COLORMAP_LEVELS = 256
#: Joints projected farther than this many image sizes outside the image are not drawn
#: (nor their bones): a point close to the camera's plane projects near infinity.
OFF_IMAGE_LIMIT = 1.0


def video_path(out: str | os.PathLike) -> Path:
    """The file a video asked for at ``out`` is written to: ``out`` with ``.mp4`` appended
    when it has no suffix. A folder or another suffix is an :class:`OutputError`."""
    out = Path(out)
    if out.is_dir():
        raise OutputError(f"{out} is a folder; give the video's file name")
    if not out.suffix:
        return out.with_name(out.name + VIDEO_SUFFIX)
    if out.suffix.lower() != VIDEO_SUFFIX:
        raise OutputError(f"{out}: videos are written as MP4; give a name ending in {VIDEO_SUFFIX}")
    return out


@lru_cache(maxsize=1)
def _colormap_table() -> np.ndarray:
    """(COLORMAP_LEVELS, 3) uint8 RGB of :data:`DEPTH_COLORMAP`, low to high."""
    import matplotlib

    rgba = matplotlib.colormaps[DEPTH_COLORMAP](np.linspace(0.0, 1.0, COLORMAP_LEVELS), bytes=True)
    return np.ascontiguousarray(rgba[:, :3])


def rgb_from_depth(depth: np.ndarray, low: float, high: float) -> np.ndarray:
    """Colour-map a depth image as :func:`occupose.viz.show_frame` does.

    depth : (H, W) float metres, 0 or NaN where there is no measurement
    low, high : metres at the two ends of the colormap (clipped beyond them)
    Returns (H, W, 3) uint8 RGB, :data:`NO_DEPTH_COLOR` where there is no measurement.
    """
    depth = np.asarray(depth, dtype=np.float64)
    if depth.ndim != 2:
        raise ValueError(f"depth must be an (H, W) image, got shape {depth.shape}")
    if not high > low:
        raise ValueError(f"the depth range must have high > low, got {low}..{high}")
    measured = np.isfinite(depth) & (depth > 0)
    scaled = (np.where(measured, depth, low) - low) / (high - low)
    levels = np.clip(np.rint(scaled * (COLORMAP_LEVELS - 1)), 0, COLORMAP_LEVELS - 1).astype(np.intp)
    image = _colormap_table()[levels]
    image[~measured] = NO_DEPTH_COLOR
    return image


class _Style:
    """The pixel sizes of the drawing for an image ``height`` rows high."""

    def __init__(self, height: int):
        scale = max(1.0, height / STYLE_HEIGHT_PX)
        self.line = max(1, round(LINE_WIDTH_PX * scale))
        self.outline = max(1, round(OUTLINE_PX * scale))
        self.radius = max(1, round(JOINT_RADIUS_PX * scale))
        self.cross = max(1, round(CROSS_HALF_PX * scale))
        self.dash = max(1, round(DASH_PX * scale))
        self.margin = round(TEXT_MARGIN_PX * scale)
        self.font = _font(round(TEXT_HEIGHT_PX * scale))


@lru_cache(maxsize=8)
def _font(size: int):
    from PIL import ImageFont

    return ImageFont.load_default(size=size)


def _dashes(a: np.ndarray, b: np.ndarray, dash: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """The drawn pieces of a dashed line from ``a`` to ``b`` ((2,) pixels): ``dash`` on, ``dash`` off."""
    length = float(np.hypot(*(b - a)))
    if length <= dash:
        return [(a, b)]
    starts = np.arange(0.0, length, 2 * dash)
    return [(a + (b - a) * s / length, a + (b - a) * min(s + dash, length) / length) for s in starts]


def _draw_skeleton(draw, uv: np.ndarray, drawn: np.ndarray, visible: np.ndarray, color, label: str,
                   style: _Style) -> None:
    """Draw one skeleton: uv (15, 2) pixels, drawn (15,) bool (joints to draw), visible (15,) bool."""
    lines = []  # (start, end) pixel pairs: solid bones, the dashes of the others, the crosses
    for a, b in BONES:
        if drawn[a] and drawn[b]:
            if visible[a] and visible[b]:
                lines.append((uv[a], uv[b]))
            else:
                lines += _dashes(uv[a], uv[b], style.dash)
    c = style.cross
    for u, v in uv[drawn & ~visible]:
        lines += [(np.array([u - c, v - c]), np.array([u + c, v + c])), (np.array([u - c, v + c]), np.array([u + c, v - c]))]
    for width, fill in ((style.line + 2 * style.outline, OUTLINE_COLOR), (style.line, color)):
        for start, end in lines:
            draw.line([tuple(start), tuple(end)], fill=fill, width=width)
    r = style.radius
    for u, v in uv[drawn & visible]:
        draw.ellipse([u - r, v - r, u + r, v + r], fill=color, outline=OUTLINE_COLOR, width=style.outline)
    head = JOINT_INDEX["head"]
    anchor = uv[head] if drawn[head] else uv[drawn][0]
    draw.text((anchor[0] + 2 * r, anchor[1] - 2 * r), label, fill=color, font=style.font, anchor="lb",
              stroke_width=style.outline, stroke_fill=OUTLINE_COLOR)


def frame_image(depth: np.ndarray, camera: Camera, joints: np.ndarray, visible: np.ndarray,
                ids: Iterable[int], text: str, depth_limits: tuple[float, float] | None = None) -> np.ndarray:
    """One frame of a video: the depth colour-mapped, the skeletons and ``text`` over it.

    depth : (H, W) float metres of ``camera`` (0 = no measurement)
    joints : (P, 15, 3) float metres, world frame, NaN where unknown; visible : (P, 15) bool
    ids : the P track ids (their colours, :func:`occupose.viz.track_color`, and labels)
    text : written at the top left (e.g. the frame number)
    depth_limits : (low, high) metres of the colormap (default: :func:`occupose.viz.depth_range` of ``depth``)
    Returns (H', W', 3) uint8 RGB, H' and W' the image's size rounded up to even (the
    video's pixel format needs it), padded with black.
    """
    from PIL import Image, ImageDraw

    joints = np.asarray(joints, dtype=np.float64)
    visible = np.asarray(visible, dtype=bool)
    ids = [int(i) for i in ids]
    if joints.ndim != 3 or joints.shape[1:] != (len(JOINT_INDEX), 3) or visible.shape != joints.shape[:2] \
            or len(ids) != joints.shape[0]:
        raise ValueError(f"expected joints (P, 15, 3), visible (P, 15) and P ids, got {joints.shape}, "
                         f"{visible.shape} and {len(ids)}")
    if np.shape(depth) != (camera.height, camera.width):
        raise ValueError(f"depth of camera {camera.name!r} must be ({camera.height}, {camera.width}), "
                         f"got {np.shape(depth)}")
    low, high = depth_range(np.asarray(depth)) if depth_limits is None else depth_limits
    height, width = camera.height + camera.height % 2, camera.width + camera.width % 2
    canvas = np.zeros((height, width, 3), np.uint8)
    canvas[:camera.height, :camera.width] = rgb_from_depth(depth, low, high)
    image = Image.fromarray(canvas)
    draw = ImageDraw.Draw(image)
    style = _Style(camera.height)
    size = np.array([camera.width, camera.height], np.float64)
    for person, track in sorted(enumerate(ids), key=lambda entry: entry[1]):
        known = np.isfinite(joints[person]).all(axis=1)
        if not known.any():
            continue
        uv, z = pixels_from_points(np.where(known[:, None], joints[person], 0.0), camera)
        with np.errstate(invalid="ignore"):
            drawn = known & (z > 0) & np.all(np.abs(uv - size / 2) <= size * (0.5 + OFF_IMAGE_LIMIT), axis=1)
        if drawn.any():
            _draw_skeleton(draw, uv, drawn, visible[person] & known, track_color(track), f"t{track}", style)
    draw.text((style.margin, style.margin), text, fill=TEXT_COLOR, font=style.font, stroke_width=style.outline,
              stroke_fill=OUTLINE_COLOR)
    return np.asarray(image)


def is_occupose_video(path: str | os.PathLike) -> bool:
    """Whether ``path`` is a video whose ``comment`` tag is :data:`VIDEO_COMMENT`."""
    from occupose.io.sources import require

    av = require("av", "kinect", "reading videos")
    try:
        with av.open(str(path)) as container:
            return container.metadata.get("comment") == VIDEO_COMMENT
    except Exception:  # anything unreadable is not a video of ours
        return False


def _video_stream(av, container, width: int, height: int, rate: Fraction):
    """The container's video stream, with the first of :data:`ENCODERS` that PyAV has."""
    for name, options in ENCODERS:
        if name in av.codecs_available:
            stream = container.add_stream(name, rate=rate)
            stream.width, stream.height, stream.pix_fmt = width, height, PIXEL_FORMAT
            stream.codec_context.time_base = 1 / rate
            if name == "mpeg4":
                stream.bit_rate = round(MPEG4_BITS_PER_PIXEL * width * height * rate)
            stream.options = dict(options)
            return stream
    raise ValueError(f"the FFmpeg inside PyAV has none of the video encoders {[name for name, _ in ENCODERS]}")


def _camera(source, name: str | None) -> Camera:
    if name is None:
        return source.cameras[0]
    for camera in source.cameras:
        if camera.name == name:
            return camera
    raise ValueError(f"{source.path}: no camera {name!r}; cameras are {[c.name for c in source.cameras]}")


def write_video(source, tracks: Mapping[int, tuple[np.ndarray, np.ndarray]], out: str | os.PathLike, *,
                camera: str | None = None, fps: float | None = None, force: bool = False,
                progress: Callable[[int], None] | None = None) -> Path:
    """Write an MP4 video of every frame of ``source`` seen by one camera, the tracks drawn
    over the depth (:func:`frame_image`; the top left says the frame number and its time).

    source : a frame source (:func:`occupose.io.sources.open_source`) with a world pose
    tracks : {track id: (joints (T, 15, 3) metres world frame, visible (T, 15) bool)} over
        the source's T frames, as read from a tracks.csv
    out : the video file (``.mp4`` is appended to a name without a suffix); an existing
        file is replaced only with ``force`` and only if occupose wrote it
        (:func:`is_occupose_video`); never one inside the recording
    camera : the camera's name (default: the source's first)
    fps : frames per second of the video (default: the recording's)
    progress : called with 1 after each frame is encoded
    The colormap's range is :func:`occupose.viz.depth_range` of the first frame, kept for
    the whole video. Returns the path written.
    """
    from occupose.io.sources import require

    av = require("av", "kinect", "writing videos")
    cam = _camera(source, camera)
    fps = source.fps if fps is None else fps
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not math.isfinite(fps) or fps <= 0:
        raise ValueError(f"fps must be a positive number, got {fps!r}")
    if source.num_frames == 0:
        raise ValueError(f"{source.path}: the recording has no frames, nothing to write")
    table = tracks_from_table(tracks, source.num_frames, source.fps)
    rate = Fraction(fps).limit_denominator(FPS_MAX_DENOMINATOR)
    out = video_path(out)
    with staged_file(out, is_occupose_video, "video", force=force, inputs=(source.path,)) as temporary:
        with av.open(str(temporary), "w", format="mp4") as container:
            container.metadata["comment"] = VIDEO_COMMENT
            stream = _video_stream(av, container, cam.width + cam.width % 2, cam.height + cam.height % 2, rate)
            limits = None
            for count, frame in enumerate(source.frames(color=False)):
                depth = frame.depth[cam.name]
                limits = depth_range(depth) if limits is None else limits
                t = frame.index
                image = frame_image(depth, cam, table.joints[t], table.visible[t], table.ids,
                                    f"frame {t}  {frame.time:.2f} s", limits)
                picture = av.VideoFrame.from_ndarray(image, format="rgb24")
                picture.pts = count
                container.mux(stream.encode(picture))
                if progress is not None:
                    progress(1)
            container.mux(stream.encode(None))
    return out


__all__ = ["ENCODERS", "VIDEO_SUFFIX", "frame_image", "is_occupose_video", "rgb_from_depth", "video_path",
           "write_video"]
