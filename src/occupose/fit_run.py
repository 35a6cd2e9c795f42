"""``occupose fit``: single depth images in, a folder of fitted skeletons out.

Each image is fitted on its own (:func:`occupose.pose.single.fit_frame`, with the same
seed: an image gives the same fit alone as among others). The output folder holds

- ``tracks.csv``: frame ``i`` is the ``i``-th image; every person of every image is a
  track of their own, numbered from 1 in image order and, within an image, left to right
  (images are not a sequence: nothing says that two of them show the same person); in the
  camera's frame (OpenCV axes: x right, y down, z forward, metres) unless the camera's
  world pose was given;
- ``<image name>.png`` per image: the depth colour-mapped with the skeletons drawn (hidden
  joints as crosses, bones to them dashed);
- ``summary.json``: the frame of the coordinates, the whole resolved config, the camera,
  and per image its people (track, body model, stature measured or taken, points, visible
  joints), the floor found in it (camera height and tilt) and the seconds its fit took.
"""

from __future__ import annotations

import dataclasses
import json
import os
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from occupose.camera import Camera
from occupose.config import TrackerConfig, as_config
from occupose.io.depth_image import read_depth_image
from occupose.io.joint_table import write_tracks_csv
from occupose.io.output import SOFTWARE, staged_folder, write_text
from occupose.joints import NUM_JOINTS
from occupose.pose.single import MODELS, FrameFit, fit_frame


def picture_names(paths: Sequence[str | os.PathLike]) -> list[str]:
    """The picture file name of each image path: its name without the suffix, plus ``.png``;
    ValueError when two images would share one."""
    names = [Path(path).stem + ".png" for path in paths]
    seen: dict[str, str] = {}
    for path, name in zip(paths, names):
        if name in seen:
            raise ValueError(f"{seen[name]} and {path} would both be pictured as {name}: give images of different "
                             f"names")
        seen[name] = str(path)
    return names


def fit_into(out: str | os.PathLike, paths: Sequence[str | os.PathLike], camera: Camera, *, world: bool = False,
             model: str = "auto", background: str | os.PathLike | None = None, depth_scale: float | None = None,
             config: TrackerConfig | str = "ours", seed: int = 0, force: bool = False,
             progress: Callable[[int], None] | None = None) -> dict:
    """Fit every image of ``paths`` (:mod:`occupose.io.depth_image`) seen by ``camera``
    (its world pose used when ``world``) and write ``out`` (module docstring) whole or not
    at all (:func:`occupose.io.output.staged_folder`). ``background`` : an image of the
    empty scene from the same camera; ``progress(1)`` after each image. Returns the summary."""
    if not paths:
        raise ValueError("no depth image given")
    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}; valid: {', '.join(MODELS)}")
    names = picture_names(paths)
    config = as_config(config)
    empty = None if background is None else read_depth_image(background, camera, depth_scale)
    inputs = [*paths, *([] if background is None else [background])]
    drawn = camera if world else dataclasses.replace(camera, world_from_camera=np.eye(4))
    frames, tracks = [], {}
    with staged_folder(out, "run", force=force, inputs=inputs) as folder:
        for index, (path, name) in enumerate(zip(paths, names)):
            depth = read_depth_image(path, camera, depth_scale)
            start = time.perf_counter()
            fit = fit_frame(depth, camera, model=model, world=world, background=empty, config=config, seed=seed)
            seconds = time.perf_counter() - start
            ids = list(range(len(tracks) + 1, len(tracks) + 1 + len(fit.people)))
            for ident, person in zip(ids, fit.people):
                tracks[ident] = (index, person)
            _write_picture(folder / name, depth, drawn, fit, ids, f"{name[:-4]}: {len(ids)} person(s)")
            frames.append(_frame_summary(index, path, name, fit, ids, seconds))
            if progress is not None:
                progress(1)
        write_tracks_csv(folder / "tracks.csv", _joint_table(tracks, len(paths)))
        summary = {"command": "fit", "frame": "world" if world else "camera", "model": model, "seed": seed,
                   "config": config.to_dict(), "camera": camera.to_dict(), "background": None if background is None else str(background),
                   "images": len(paths), "people": len(tracks), "frames": frames}
        write_text(folder / "summary.json", json.dumps(summary, indent=2) + "\n")
    return summary


def _joint_table(tracks: dict, num_frames: int) -> dict:
    """{track: (joints (F, 15, 3), visible (F, 15))}, each track known in its one frame."""
    table = {}
    for ident, (index, person) in tracks.items():
        joints = np.full((num_frames, NUM_JOINTS, 3), np.nan)
        visible = np.zeros((num_frames, NUM_JOINTS), bool)
        joints[index], visible[index] = person.joints, person.visible
        table[ident] = (joints, visible)
    return table


def _frame_summary(index: int, path, name: str, fit: FrameFit, ids: list[int], seconds: float) -> dict:
    floor = None if fit.floor is None else {"camera_height_m": round(fit.floor[0], 4),
                                            "tilt_deg": round(fit.floor[1], 3)}
    people = [{"track": ident, "model": person.model, "stature_m": round(person.stature, 3),
               "points": int(len(person.pixels)), "visible_joints": int(person.visible.sum())}
              for ident, person in zip(ids, fit.people)]
    return {"frame": index, "image": str(path), "picture": name, "floor": floor, "people": people,
            "seconds": round(seconds, 4)}


def _write_picture(path: Path, depth: np.ndarray, camera: Camera, fit: FrameFit, ids: list[int], text: str) -> None:
    from PIL import Image, PngImagePlugin

    from occupose.viz_video import frame_image

    joints = np.array([p.joints for p in fit.people]).reshape(-1, NUM_JOINTS, 3)
    visible = np.array([p.visible for p in fit.people], bool).reshape(-1, NUM_JOINTS)
    info = PngImagePlugin.PngInfo()
    info.add_text("Software", SOFTWARE)
    Image.fromarray(frame_image(depth, camera, joints, visible, ids, text)).save(path, format="PNG", pnginfo=info)
