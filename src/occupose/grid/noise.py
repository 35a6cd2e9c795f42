"""Each camera's depth noise and far range for the grid (``grid.noise_model``, ``grid.max_range``).

Every camera gets its own: with ``grid.noise_model`` preset (or none), the noise model of the sensor
preset it matches (:func:`occupose.camera.matching_preset`, within
``grid.preset_tolerance``), else :data:`occupose.grid.occupancy.DEFAULT_NOISE_MODEL`; with
a model's name, that model; with ``measured``, its own
:class:`occupose.sensors.NoiseEstimate` from the first ``grid.noise_frames`` frames
(:func:`measure_noise`; a camera whose frames allow no estimate gets its preset's, and
``summary.json`` says why: ``unmeasured``). Its far range is
``grid.max_range`` when that is set, else its preset's far range, else (measured) the
farthest depth it measured, else :data:`occupose.grid.occupancy.DEFAULT_MAX_RANGE`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from occupose.camera import CAMERA_PRESETS, Camera, matching_preset
from occupose.config import GridConfig
from occupose.grid.occupancy import DEFAULT_MAX_RANGE, DEFAULT_NOISE_MODEL
from occupose.sensors import NoiseEstimate, depth_std_coefficients, estimate_depth_noise


@dataclass(frozen=True, eq=False)
class CameraNoise:
    """What the grid assumes of one camera.

    model : a noise model name of :mod:`occupose.sensors` or the camera's NoiseEstimate
    max_range : float, metres, how far along its optical axis its view is kept
    preset : str or None, the sensor preset it matched
    unmeasured : with ``grid.noise_model`` measured, why this camera has its named model
        instead (its frames allowed no estimate), else None
    """

    model: str | NoiseEstimate
    max_range: float
    preset: str | None
    unmeasured: str | None = None

    def to_dict(self) -> dict:
        """Plain data for ``summary.json``: model ("measured" or the name), the std's
        coefficients c0, c1, c2 (metres), max range, preset, and a measurement's pixels,
        frames, depth range and bins."""
        if isinstance(self.model, NoiseEstimate):
            return {"model": "measured", **self.model.to_dict(), "max_range": self.max_range, "preset": self.preset}
        out = {"model": self.model, "coefficients": depth_std_coefficients(self.model).tolist(),
               "max_range": self.max_range, "preset": self.preset}
        return out if self.unmeasured is None else out | {"unmeasured": self.unmeasured}


def camera_noise(cameras: Sequence[Camera], config: GridConfig,
                 measured: Mapping[str, NoiseEstimate | str] | None = None) -> dict[str, CameraNoise]:
    """Camera name -> CameraNoise for every camera (module docstring).

    measured : camera name -> NoiseEstimate, or the reason it could not be measured
        (:func:`measure_noise`), used when ``config.noise_model`` is ``"measured"``: a
        camera without an estimate gets its named model (as ``noise_model`` preset), with
        the reason (``unmeasured``; "not measured" when it is not in ``measured``).
    """
    out = {}
    for cam in cameras:
        preset = matching_preset(cam, config.preset_tolerance)
        spec = None if preset is None else CAMERA_PRESETS[preset]
        unmeasured = None
        if config.noise_model == "measured" and isinstance(estimate := (measured or {}).get(cam.name),
                                                           NoiseEstimate):
            model = estimate
        elif config.noise_model == "measured":
            model = spec.noise if spec is not None else DEFAULT_NOISE_MODEL
            unmeasured = estimate if isinstance(estimate, str) else "not measured"
        elif config.noise_model not in (None, "preset"):
            model = config.noise_model
        else:
            model = spec.noise if spec is not None else DEFAULT_NOISE_MODEL
        if config.max_range is not None:
            far = config.max_range
        elif spec is not None:
            far = spec.far
        elif isinstance(model, NoiseEstimate):
            far = model.far
        else:
            far = DEFAULT_MAX_RANGE
        out[cam.name] = CameraNoise(model, float(far), preset, unmeasured)
    return out


def measure_noise(cameras: Sequence[Camera], depths: Iterable[Mapping[str, np.ndarray]],
                  config: GridConfig = GridConfig(), *, strict: bool = True) -> dict[str, NoiseEstimate | str]:
    """Camera name -> NoiseEstimate of each camera, from the first ``config.noise_frames``
    of ``depths`` (an iterable of camera name -> (H, W) float32 metres frames, 0 = no
    measurement; fewer frames are used when it ends sooner), with the ``grid.noise_*``
    settings (:func:`occupose.sensors.estimate_depth_noise`). When a camera's frames do not
    allow an estimate (fewer than 3, no depth bin with enough static pixels): a ValueError
    naming it, or, not ``strict``, the reason (str) in its place (:func:`camera_noise`
    then gives it its named model)."""
    stacks: dict[str, list[np.ndarray]] = {c.name: [] for c in cameras}
    for count, frame in enumerate(depths):
        if count >= config.noise_frames:
            break
        for name, images in stacks.items():
            images.append(np.asarray(frame[name]))
    out = {}
    for name, images in stacks.items():
        try:
            out[name] = estimate_depth_noise(np.stack(images) if images else np.zeros((0, 1, 1)),
                                             bin_width=config.noise_bin, static_cut=config.noise_static_cut,
                                             min_pixels=config.noise_min_pixels)
        except ValueError as error:
            if strict:
                raise ValueError(f"camera {name!r}: {error}") from None
            out[name] = str(error)
    return out
