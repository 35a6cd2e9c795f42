"""Render a scenario frame by frame: images, noisy depth, and ground truth with visibility.

Ground-truth visibility: in every frame each body part is also rendered alone (no
furniture, no other people, no other part of the same body). A part is *visible* in a
camera when at least half of the pixels it covers alone are still its own in the full
scene and measured by the sensor (noisy depth > 0; and at least ``MIN_PART_PIXELS``), so
furniture, other people, the person's own body (an arm behind the torso), the sensor's
working range and its dropouts all hide it; a joint is visible when the part that starts
at it (:data:`occupose.joints.JOINT_PART`) is visible to a camera whose image the joint
projects into. A person is *present*
in a frame when any camera covers any pixel of their parts alone, i.e. when they are inside
some camera's view, hidden or not; ground-truth rows are written only for present people.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from occupose.camera import pixels_from_points, raw_depth_from_metres
from occupose.joints import JOINT_PART, PARTS
from occupose.io.recording import RecordingWriter
from occupose.synth.body import primitives_from_joints
from occupose.synth.noise import apply_noise
from occupose.geometry.primitives import Primitives, concat, select
from occupose.synth.render import Rendered, render_camera
from occupose.synth.scenarios import Scenario

MIN_PART_PIXELS = 4
#: File of a synthetic recording that describes its scene (JSON; see :func:`write_scenario`).
SCENE_FILE = "scene.json"


@dataclass(frozen=True)
class SynthFrame:
    """One rendered frame of a scenario.

    rendered : per camera name, the noise-free images (depth metres, colour, person, part)
    depth : per camera name, (H, W) float32 metres after the sensor noise model (0 = invalid)
    joints : (P, 15, 3) float64 world metres; visible : (P, 15) bool; present : (P,) bool
    """

    index: int
    rendered: dict[str, Rendered]
    depth: dict[str, np.ndarray]
    joints: np.ndarray
    visible: np.ndarray
    present: np.ndarray


def _part_counts(rendered: Rendered, person: int, measured: np.ndarray) -> np.ndarray:
    """(len(PARTS),) pixel count of each body part of ``person`` in a rendered image, counting
    only the pixels the sensor measured (``measured``: (H, W) bool, the noisy depth > 0), so a
    part beyond the working range or lost to dropouts is not seen."""
    mask = (rendered.person == person) & measured
    return np.bincount(rendered.part[mask].ravel(), minlength=len(PARTS))


def _in_image(points: np.ndarray, camera) -> np.ndarray:
    """(N,) bool: which world points (N, 3) project inside the camera's image, in front of it."""
    uv, z = pixels_from_points(points, camera)
    u, v = np.round(uv[:, 0]), np.round(uv[:, 1])
    return (z > 0) & (u >= 0) & (u < camera.width) & (v >= 0) & (v < camera.height)


def _alone_counts(body: Primitives, camera) -> np.ndarray:
    """(len(PARTS),) pixels each body part covers when rendered by itself."""
    counts = np.zeros(len(PARTS), np.int64)
    for part in np.unique(body.part):
        counts[part] = np.count_nonzero(render_camera(select(body, body.part == part), camera).person)
    return counts


def frames(scenario: Scenario, seed: int = 0, num_frames: int | None = None,
           indices=None) -> Iterator[SynthFrame]:
    """Render the scenario's frames in order (lazily).

    seed : seeds the sensor noise (the scenario's own randomness is fixed when it is built)
    num_frames : render only the first ``num_frames`` frames (default: all)
    indices : or render only these frame indices (e.g. every tenth frame, for tests)
    """
    total = scenario.num_frames if num_frames is None else int(num_frames)
    if not 0 < total <= scenario.num_frames:
        raise ValueError(f"num_frames must be in 1..{scenario.num_frames}, got {num_frames}")
    indices = range(total) if indices is None else [int(i) for i in indices]
    if any(not 0 <= i < scenario.num_frames for i in indices):
        raise ValueError(f"frame indices must be in 0..{scenario.num_frames - 1}")
    rng = np.random.default_rng(seed)
    static_bg = {cam.name: render_camera(scenario.static, cam) for cam in scenario.cameras}
    num_people = len(scenario.people)
    for t in indices:
        bodies = [primitives_from_joints(p.joints[t], p.shape, i + 1) for i, p in enumerate(scenario.people)]
        moving = scenario.moving_at(t)
        visible = np.zeros((num_people, len(JOINT_PART)), bool)
        present = np.zeros(num_people, bool)
        rendered, depth = {}, {}
        for cam in scenario.cameras:
            bg = static_bg[cam.name] if len(moving) == 0 else render_camera(moving, cam, background=static_bg[cam.name])
            full = render_camera(concat(bodies), cam, background=bg)
            rendered[cam.name] = full
            model, options = scenario.noise[cam.name]
            depth[cam.name] = apply_noise(full.depth, model, rng, fx=cam.fx, person=full.person, **options)
            for i, body in enumerate(bodies):
                alone = _alone_counts(body, cam)
                seen = _part_counts(full, i + 1, depth[cam.name] > 0)
                present[i] |= alone[1:].sum() > 0
                part_visible = (alone > 0) & (seen >= np.maximum(0.5 * alone, MIN_PART_PIXELS))
                visible[i] |= part_visible[list(JOINT_PART)] & _in_image(scenario.people[i].joints[t], cam)
        joints = np.stack([p.joints[t] for p in scenario.people]) if num_people else np.zeros((0, 15, 3))
        yield SynthFrame(t, rendered, depth, joints, visible, present)


def write_scenario(scenario: Scenario, out: str | Path, seed: int = 0, num_frames: int | None = None,
                   progress=None) -> Path:
    """Render a scenario into a recording folder (DESIGN.md format) with ground truth.

    Besides depth, colour and ``groundtruth.csv``, the synthetic recording keeps the
    renderer's label images: ``<camera>/person/NNNNNN.png`` (8-bit person id, 0 = none)
    and ``<camera>/part/NNNNNN.png`` (8-bit body-part label of :data:`occupose.joints.PARTS`),
    and :data:`SCENE_FILE`: the scenario's name, description, motion source, events and
    ``conditions`` (what a randomized scene drew), so runs can be bucketed by them.
    progress : optional callable ``progress(n)`` called after each frame.
    """
    out = Path(out)
    total = scenario.num_frames if num_frames is None else int(num_frames)
    num_people = len(scenario.people)
    gt = np.full((total, num_people, 15, 3), np.nan)
    vis = np.zeros((total, num_people, 15), bool)
    with RecordingWriter(out, list(scenario.cameras), scenario.fps) as writer:
        for frame in frames(scenario, seed, total):
            writer.write_frame(
                {cam.name: raw_depth_from_metres(frame.depth[cam.name], cam) for cam in scenario.cameras},
                {name: r.color for name, r in frame.rendered.items()},
                labels={name: {"person": r.person.astype(np.uint8), "part": r.part}
                        for name, r in frame.rendered.items()},
            )
            gt[frame.index, frame.present] = frame.joints[frame.present]
            vis[frame.index] = frame.visible & frame.present[:, None]
            if progress is not None:
                progress(1)
        writer.write_groundtruth(gt, vis, person_ids=list(range(1, num_people + 1)))
    scene = {"name": scenario.name, "description": scenario.description, "frames": total,
             "motion_source": scenario.motion_source, "events": {k: list(v) for k, v in scenario.events.items()},
             "conditions": scenario.conditions}
    (out / SCENE_FILE).write_text(json.dumps(scene, indent=1) + "\n")
    return out
