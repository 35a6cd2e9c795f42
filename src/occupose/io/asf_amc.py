"""CMU ASF/AMC files: an ASF skeleton and an AMC motion as a :class:`occupose.io.mocap.Clip`.

Units: an ASF file declares its own (``:units length L``: 1 unit = 0.0254 / L m).

Rotations follow the CMU viewer: a bone's world rotation is ``parent @ C @ M @ C^-1`` with
``C`` from the bone's ``axis`` and ``M`` from the frame's dof values, both applied in the
order written (``axis ... XYZ`` and ``dof rx ry rz`` mean Rz Ry Rx, x applied first).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import NamedTuple

import numpy as np

from occupose.io._skeleton import matrices_from_euler, metres_per_unit, positions_from_kinematics, zup_from_yup
from occupose.io.mocap import Clip


class _Bone(NamedTuple):
    name: str
    direction: np.ndarray  # (3,) unit, file frame
    length: float
    axis: np.ndarray  # (3,) angles
    axis_order: str  # e.g. "xyz"
    dof: tuple[str, ...]  # e.g. ("rx", "ry", "rz")


def load_asf_amc(asf_path, amc_path, units="auto") -> Clip:
    """Load a CMU ASF skeleton and an AMC motion into a :class:`Clip` (world metres, z up).

    The clip's joints are ``root`` (the root's position) and one joint per ASF bone, at
    that bone's far end: ``lhipjoint`` is the left hip joint, ``lfemur`` the knee,
    ``ltibia`` the ankle, ``lclavicle`` the shoulder, ``lhumerus`` the elbow, ``lwrist``
    the wrist (``lradius`` ends 0.1 m short of it: ``lwrist`` is the forearm's twist
    segment, the hand's flexion starts at its end), ``lowerneck`` the neck, ``upperneck``
    the base of the head, ``head`` the end of the head bone. fps is 120 (the CMU capture
    rate; AMC files do not store it).

    units : ``"auto"`` (from the ASF's ``:units length L``, 1 unit = 0.0254 / L m) or
        metres per file unit.
    """
    asf_path, amc_path = Path(asf_path), Path(amc_path)
    for p in (asf_path, amc_path):
        if not p.is_file():
            raise FileNotFoundError(f"ASF/AMC file {p} does not exist")
    root, bones, hierarchy, length_unit, degrees = _parse_asf(asf_path)
    if isinstance(units, str) and units == "auto":
        if length_unit is None:
            raise ValueError(f"{asf_path}: no ':units length' to pick units from; pass units=")
        scale = 0.0254 / length_unit
    else:
        scale = metres_per_unit(units)

    # Parent-first order by walking the hierarchy from the root.
    names, parents = ["root"], [-1]
    stack = [("root", 0)]
    while stack:
        parent, pidx = stack.pop()
        for child in reversed(hierarchy.get(parent, ())):
            if child not in bones or child in names:
                raise ValueError(f"{asf_path}: hierarchy names bone {child!r} twice or without bonedata")
            names.append(child)
            parents.append(pidx)
            stack.append((child, len(names) - 1))

    dof_names = {"root": root["order"]} | {b.name: b.dof for b in bones.values()}
    frames = _parse_amc(amc_path, dof_names)
    num_frames = len(frames)

    locals_ = []
    vectors = np.zeros((num_frames, len(names), 3))
    for j, name in enumerate(names):
        values = np.array([frame[name] for frame in frames]).reshape(num_frames, -1)
        dof = dof_names[name]
        rot = [k for k, d in enumerate(dof) if d.startswith("r")]
        letters = "".join(dof[k][1] for k in rot)
        motion = matrices_from_euler(letters, values[:, rot], degrees, intrinsic=False)
        if name == "root":
            c = matrices_from_euler(root["axis_order"], root["orientation"][None], degrees, False)[0]
            for k, d in enumerate(dof):
                if d.startswith("t"):
                    vectors[:, j, "xyz".index(d[1])] = values[:, k]
            vectors[:, j] += root["position"]
        else:
            bone = bones[name]
            c = matrices_from_euler(bone.axis_order, bone.axis[None], degrees, intrinsic=False)[0]
            vectors[:, j] = bone.length * bone.direction
        locals_.append(c @ motion @ c.T)
    positions = positions_from_kinematics(np.asarray(parents), vectors, locals_, own_frame=True)
    return Clip(
        names=tuple(names),
        parents=np.asarray(parents, dtype=np.int64),
        fps=120.0,
        positions=zup_from_yup(positions) * scale,
        source="asf",
    )


def _parse_asf(path: Path):
    """(root dict, bones by name, hierarchy parent -> children, length unit or None, degrees)."""
    lines = path.read_text(errors="replace").splitlines()
    section = None
    root = {"order": (), "axis_order": "xyz", "position": np.zeros(3), "orientation": np.zeros(3)}
    bones: dict[str, _Bone] = {}
    hierarchy: dict[str, list[str]] = {}
    length_unit, degrees = None, True
    current: dict | None = None

    def fail(n: int, message: str) -> ValueError:
        return ValueError(f"{path}:{n}: malformed ASF: {message}")

    def floats(n: int, words: list[str], count: int) -> np.ndarray:
        try:
            values = np.array([float(w) for w in words[:count]])
        except ValueError:
            raise fail(n, f"expected {count} numbers, got {' '.join(words)!r}") from None
        if values.size != count:
            raise fail(n, f"expected {count} numbers, got {' '.join(words)!r}")
        return values

    for n, raw in enumerate(lines, 1):
        words = raw.split()
        if not words or words[0].startswith("#"):
            continue
        key = words[0]
        if key.startswith(":"):
            section = key[1:]
            continue
        if section == "units":
            if key == "length":
                length_unit = float(floats(n, words[1:], 1)[0])
            elif key == "angle":
                degrees = words[1].lower().startswith("deg")
        elif section == "root":
            if key == "order":
                root["order"] = tuple(w.lower() for w in words[1:])
                bad = [d for d in root["order"] if d not in ("tx", "ty", "tz", "rx", "ry", "rz")]
                if bad:
                    raise fail(n, f"root order may hold TX TY TZ RX RY RZ, got {bad}")
            elif key == "axis":
                root["axis_order"] = words[1].lower()
            elif key in ("position", "orientation"):
                root[key] = floats(n, words[1:], 3)
        elif section == "bonedata":
            if key == "begin":
                current = {"dof": (), "line": n}
            elif key == "end":
                if current is None or not {"name", "direction", "length", "axis"} <= set(current):
                    raise fail(n, "bone block without name, direction, length and axis")
                norm = np.linalg.norm(current["direction"])
                bones[current["name"]] = _Bone(
                    current["name"], current["direction"] / (norm if norm > 0 else 1.0),
                    current["length"], current["axis"], current["axis_order"], current["dof"],
                )
                current = None
            elif current is None:
                raise fail(n, f"{key!r} outside a begin/end bone block")
            elif key == "name":
                current["name"] = words[1]
            elif key == "direction":
                current["direction"] = floats(n, words[1:], 3)
            elif key == "length":
                current["length"] = float(floats(n, words[1:], 1)[0])
            elif key == "axis":
                current["axis"] = floats(n, words[1:], 3)
                current["axis_order"] = words[4].lower() if len(words) > 4 else "xyz"
            elif key == "dof":
                dof = tuple(w.lower() for w in words[1:])
                bad = [d for d in dof if d not in ("rx", "ry", "rz")]
                if bad:
                    raise fail(n, f"only rotational dof (rx, ry, rz) are supported for bones, got {bad}")
                current["dof"] = dof
        elif section == "hierarchy" and key not in ("begin", "end"):
            hierarchy.setdefault(key, []).extend(words[1:])
    if not bones or "root" not in hierarchy:
        raise ValueError(f"{path}: malformed ASF: no bonedata or no hierarchy from 'root'")
    return root, bones, hierarchy, length_unit, degrees


def _parse_amc(path: Path, dof_names: dict[str, tuple[str, ...]]) -> list[dict[str, list[float]]]:
    """One dict per frame: bone name -> its dof values (bones missing from a frame: zeros)."""
    frames: list[dict[str, list[float]]] = []
    defaults = {name: [0.0] * len(d) for name, d in dof_names.items()}
    for n, raw in enumerate(path.read_text(errors="replace").splitlines(), 1):
        words = raw.split()
        if not words or words[0].startswith(("#", ":")):
            continue
        if len(words) == 1 and re.fullmatch(r"\d+", words[0]):
            frames.append(dict(defaults))
            continue
        if not frames:
            raise ValueError(f"{path}:{n}: malformed AMC: bone values before the first frame number")
        name = words[0]
        if name not in dof_names:
            raise ValueError(f"{path}:{n}: malformed AMC: bone {name!r} is not in the ASF skeleton")
        if len(words) - 1 != len(dof_names[name]):
            raise ValueError(f"{path}:{n}: malformed AMC: bone {name!r} has {len(dof_names[name])} dof "
                             f"in the ASF, got {len(words) - 1} values")
        try:
            frames[-1][name] = [float(w) for w in words[1:]]
        except ValueError:
            raise ValueError(f"{path}:{n}: malformed AMC: non-numeric value for {name!r}") from None
    if not frames:
        raise ValueError(f"{path}: malformed AMC: no frames")
    return frames
