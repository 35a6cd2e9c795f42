"""Pictures of recordings: a colour-mapped depth image with skeletons drawn over it."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from occupose.camera import pixels_from_points
from occupose.joints import BONES
from occupose.io.output import SOFTWARE, picture_path, staged_picture
from occupose.io.recording import Recording

#: The matplotlib colormap of depth images (every picture, video and rerun recording).
DEPTH_COLORMAP = "turbo"
#: Depth range of the colormap, metres: its low end, and the least its high end is
#: (higher when the image has farther depths: :func:`depth_range`).
DEPTH_RANGE_M = (0.5, 4.5)
#: Colours of tracked skeletons (8-bit RGB), by track id (:func:`track_color`): none of
#: them in the depth colormap, so a skeleton stands out on any depth.
TRACK_COLORS = ((255, 255, 255), (255, 43, 214), (0, 229, 255), (255, 152, 0), (125, 255, 106), (160, 120, 255))


def _depth_colors():
    import matplotlib

    return matplotlib.colormaps[DEPTH_COLORMAP].with_extremes(bad="black")


def depth_range(depth: np.ndarray) -> tuple[float, float]:
    """(low, high) metres of the depth colormap for ``depth`` ((H, W) metres, 0 or NaN =
    none): :data:`DEPTH_RANGE_M`, its high end raised to the farthest depth."""
    measured = depth[np.isfinite(depth) & (depth > 0)]
    farthest = float(measured.max()) if measured.size else 0.0
    return DEPTH_RANGE_M[0], max(DEPTH_RANGE_M[1], farthest)


def track_color(track: int) -> tuple[int, int, int]:
    """The 8-bit RGB colour of track id ``track`` (ids from 1): :data:`TRACK_COLORS` in turn."""
    return TRACK_COLORS[(int(track) - 1) % len(TRACK_COLORS)]


def _figure(width: int, height: int, panels: int):
    """A matplotlib Figure (no pyplot, so no global backend state) with ``panels`` axes."""
    from matplotlib.figure import Figure

    scale = 6.0 / width
    fig = Figure(figsize=(panels * width * scale, height * scale + 0.5))
    return fig, fig.subplots(1, panels, squeeze=False)[0]


def draw_skeleton(ax, uv: np.ndarray, visible: np.ndarray, color: str, label: str | None = None) -> None:
    """Draw one skeleton on an image axis.

    uv : (15, 2) pixel coordinates (NaN for joints not drawn); visible : (15,) bool.
    Visible joints are filled dots with solid bones; hidden joints crosses with dashed bones.
    """
    for a, b in BONES:
        if np.all(np.isfinite(uv[[a, b]])):
            style = "-" if visible[a] and visible[b] else "--"
            ax.plot(uv[[a, b], 0], uv[[a, b], 1], style, color=color, lw=1.6, alpha=0.9)
    ok = np.all(np.isfinite(uv), axis=1)
    ax.scatter(uv[ok & visible, 0], uv[ok & visible, 1], s=18, c=color, edgecolors="k", linewidths=0.5,
               zorder=3, label=label)
    ax.scatter(uv[ok & ~visible, 0], uv[ok & ~visible, 1], s=26, c=color, marker="x", linewidths=1.6, zorder=3)


def show_frame(recording: Recording, index: int, out: str | Path, tracks: dict | None = None, *,
               force: bool = False) -> Path:
    """Write a PNG of frame ``index``: for every camera, the depth image colour-mapped
    (black = no measurement) with the ground-truth skeletons over it (hidden joints as
    crosses, bones to them dashed; ``visible`` is the ground truth's flag, i.e. seen by
    *some* camera, so with several cameras a joint drawn visible may be hidden in this one) and, when given, tracked skeletons.

    tracks : optional {track id: (joints (T, 15, 3), visible (T, 15))} as read from a tracks.csv.
    out : the PNG file (``.png`` is appended to a name without a suffix); an existing file
        is replaced only with ``force`` and only if occupose wrote it, and never a file
        inside the recording (:func:`occupose.io.output.staged_picture`).
    Returns the path written.
    """
    if not 0 <= index < recording.num_frames:
        raise ValueError(f"frame {index} is out of range: {recording.path} has frames 0..{recording.num_frames - 1}")
    out = picture_path(out)
    with staged_picture(out, force=force, inputs=(recording.path,)) as temporary:
        _draw_frame(recording, index, tracks).savefig(temporary, format="png", dpi=110, bbox_inches="tight",
                                                      metadata={"Software": SOFTWARE})
    return out


def _draw_frame(recording: Recording, index: int, tracks: dict | None):
    """The matplotlib Figure of :func:`show_frame`."""
    frame = recording.frame(index)
    gt = recording.groundtruth() if recording.has_groundtruth else None
    cams = recording.cameras
    fig, axes = _figure(cams[0].width, cams[0].height, len(cams))
    colors = ["#ff2bd6", "#ffffff", "#7dff6a", "#ffd23f"]
    for ax, cam in zip(axes, cams):
        depth = np.where(frame.depth[cam.name] > 0, frame.depth[cam.name], np.nan)
        low, high = depth_range(depth)
        im = ax.imshow(depth, cmap=_depth_colors(), vmin=low, vmax=high)
        ax.set_title(f"{recording.path.name} — {cam.name} — frame {index}", fontsize=8)
        ax.set_xlim(0, cam.width)
        ax.set_ylim(cam.height, 0)
        ax.axis("off")
        fig.colorbar(im, ax=ax, fraction=0.035, pad=0.01, label="depth [m]")
        if gt is not None:
            for p in range(gt.joints.shape[1]):
                joints = gt.joints[index, p]
                if not np.all(np.isfinite(joints)):
                    continue
                uv, z = pixels_from_points(joints, cam)
                uv[z <= 0] = np.nan
                draw_skeleton(ax, uv, gt.visible[index, p], colors[p % len(colors)],
                              label=f"truth person {gt.person_ids[p]}")
        for k, (track, (joints, visible)) in enumerate(sorted((tracks or {}).items())):
            if index < len(joints) and np.any(np.isfinite(joints[index])):
                uv, z = pixels_from_points(np.nan_to_num(joints[index], nan=0.0), cam)
                uv[~np.isfinite(joints[index]).all(axis=1) | (z <= 0)] = np.nan
                draw_skeleton(ax, uv, visible[index], "#00e5ff" if k == 0 else "#ff9800", label=f"track {track}")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(loc="lower left", fontsize=6, framealpha=0.6)
    return fig
