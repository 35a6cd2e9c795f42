"""Each camera's depth noise and far range for the grid (``grid.noise_model``, ``grid.max_range``).

Every camera gets its own: with ``grid.noise_model`` none, the noise model of the sensor
preset it matches (:func:`occupose.camera.matching_preset`, within
``grid.preset_tolerance``), else :data:`occupose.grid.occupancy.DEFAULT_NOISE_MODEL`; with
a model's name, that model; with ``measured``, its own :class:`occupose.sensors.NoiseEstimate`
from the first ``grid.noise_frames`` frames (:func:`measure_noise`). Its far range is
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
    """

    model: str | NoiseEstimate
    max_range: float
    preset: str | None

    def to_dict(self) -> dict:
        """Plain data for ``summary.json``: model ("measured" or the name), the std's
        coefficients c0, c1, c2 (metres), max range, preset, and a measurement's pixels,
        frames, depth range and bins."""
        if isinstance(self.model, NoiseEstimate):
            return {"model": "measured", **self.model.to_dict(), "max_range": self.max_range, "preset": self.preset}
        return {"model": self.model, "coefficients": depth_std_coefficients(self.model).tolist(),
                "max_range": self.max_range, "preset": self.preset}


def camera_noise(cameras: Sequence[Camera], config: GridConfig,
                 measured: Mapping[str, NoiseEstimate] | None = None) -> dict[str, CameraNoise]:
    """Camera name -> CameraNoise for every camera (module docstring).

    measured : camera name -> NoiseEstimate (:func:`measure_noise`), required for every
        camera when ``config.noise_model`` is ``"measured"`` and not used otherwise.
    """
    if config.noise_model == "measured":
        missing = [c.name for c in cameras if measured is None or c.name not in measured]
        if missing:
            raise ValueError(f"grid.noise_model 'measured' needs the measured noise of camera(s) {missing} "
                             f"(occupose.grid.noise.measure_noise of the first grid.noise_frames frames)")
    out = {}
    for cam in cameras:
        preset = matching_preset(cam, config.preset_tolerance)
        spec = None if preset is None else CAMERA_PRESETS[preset]
        if config.noise_model == "measured":
            model = measured[cam.name]
        elif config.noise_model is not None:
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
        out[cam.name] = CameraNoise(model, float(far), preset)
    return out


def measure_noise(cameras: Sequence[Camera], depths: Iterable[Mapping[str, np.ndarray]],
                  config: GridConfig = GridConfig()) -> dict[str, NoiseEstimate]:
    """Camera name -> NoiseEstimate of each camera, from the first ``config.noise_frames``
    of ``depths`` (an iterable of camera name -> (H, W) float32 metres frames, 0 = no
    measurement; fewer frames are used when it ends sooner), with the ``grid.noise_*``
    settings (:func:`occupose.sensors.estimate_depth_noise`). Raises ValueError naming the
    camera when its frames do not allow an estimate."""
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
            raise ValueError(f"camera {name!r}: {error}") from None
    return out
