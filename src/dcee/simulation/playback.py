"""Playback of a recorded or externally simulated plume as ground truth.

A recording is a concentration array (g/m³) shaped ``(T, ny, nx)`` or ``(T, ny, nx, nz)`` with
strictly increasing coordinate vectors ``t`` (s), ``y``, ``x`` and optionally ``z`` (m):

* ``.h5``: datasets ``concentration``, ``t``, ``x``, ``y`` and optionally ``z``; an optional
  attribute ``source`` (3 numbers, m) is checked against the scenario's true source.
* ``.npy``: the array; the metadata in a JSON file beside it with the same stem
  (``plume.npy`` + ``plume.json``) holding ``t``, ``x``, ``y``, optionally ``z`` and ``source``.

A planar recording (no z axis) may name the height of its plane: a number ``z`` in the JSON, an
attribute ``z`` of the .h5 file, a scalar height coordinate in NetCDF
(:func:`dcee.recordings.recording_layout`); the agent must then fly at that height.

:func:`save_recording` writes either format. Space is interpolated trilinearly (bilinearly for a
2-D recording, which then holds at every altitude); time by the nearest frame or linearly
between frames. Episode time 0 is the first frame. With ``loop`` the recording repeats with
period ``t[-1] - t[0] + (t[-1] - t[-2])`` (the last frame lasts as long as the frame interval
before it); without it, asking past the last frame is an error. Positions outside the grid are
an error, never extrapolated: a search must stay where the data are.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.limits import check_declared, check_npy, read_text
from dcee.recordings import is_cf
from dcee.recordings.cf import read_cf_recording
from dcee.simulation.truth import TruthModel, register_truth

if TYPE_CHECKING:
    from dcee.scenarios import Scenario

FIELD = "truth.model.file"


def _fail(msg: str) -> DceeInputError:
    return DceeInputError(FIELD, msg)


def _axis(name: str, values: object, size: int) -> np.ndarray:
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise _fail(f"metadata {name!r} must be a list of numbers") from None
    if arr.ndim != 1 or arr.size != size:
        raise _fail(f"metadata {name!r} has {arr.size} values; the array's {name} axis has {size}")
    if not np.all(np.isfinite(arr)) or (size > 1 and not np.all(np.diff(arr) > 0)):
        raise _fail(f"metadata {name!r} must be finite and strictly increasing")
    return arr


class PlaybackTruth(TruthModel):
    """A recorded concentration field.

    Parameters
    ----------
    concentration : (T, ny, nx) or (T, ny, nx, nz) array, g/m³, finite and >= 0.
    t, x, y, z : coordinate vectors (s, m); ``z`` only with a 4-D array.
    time_interpolation : "nearest" or "linear".
    loop : repeat the recording past its end.
    """

    name = "playback"
    label = "recorded plume"

    def __init__(
        self,
        concentration: np.ndarray,
        t: np.ndarray,
        x: np.ndarray,
        y: np.ndarray,
        z: np.ndarray | None = None,
        time_interpolation: str = "linear",
        loop: bool = False,
    ) -> None:
        c = np.asarray(concentration, dtype=np.float64)
        if c.ndim not in (3, 4):
            raise _fail(
                f"the array must be time × y × x or time × y × x × z; got {c.ndim} dimension(s) "
                f"{c.shape}"
            )
        if (c.ndim == 4) != (z is not None):
            raise _fail("a 4-D array needs 'z' metadata and a 3-D array must not have it")
        if min(c.shape) < 1 or any(n < 2 for n in c.shape[1:]):
            raise _fail(f"every spatial axis needs at least 2 grid points; got shape {c.shape}")
        if not np.all(np.isfinite(c)) or np.any(c < 0):
            raise _fail("concentrations must be finite and >= 0")
        if time_interpolation not in ("nearest", "linear"):
            raise _fail(
                f"time_interpolation must be 'nearest' or 'linear' (got {time_interpolation!r})"
            )
        self.values = c
        self.t = _axis("t", t, c.shape[0])
        self.y = _axis("y", y, c.shape[1])
        self.x = _axis("x", x, c.shape[2])
        self.z = None if z is None else _axis("z", z, c.shape[3])
        self.time_interpolation = time_interpolation
        self.loop = loop
        self.duration = float(self.t[-1] - self.t[0])
        last = float(self.t[-1] - self.t[-2]) if len(self.t) > 1 else 0.0
        self.period = self.duration + last

    @property
    def time_step(self) -> float | None:
        """The shortest frame interval (None for a single frame)."""
        return float(np.min(np.diff(self.t))) if len(self.t) > 1 else None

    # --- geometry ---------------------------------------------------------------------------

    def covers(self, low: np.ndarray, high: np.ndarray) -> str | None:
        """None if the grid covers the box [low, high] (m), else which axis does not."""
        axes = [("x", self.x, 0), ("y", self.y, 1)]
        if self.z is not None:
            axes.append(("z", self.z, 2))
        for name, coords, k in axes:
            if low[k] < coords[0] - 1e-9 or high[k] > coords[-1] + 1e-9:
                return (
                    f"the grid's {name} range [{coords[0]:g}, {coords[-1]:g}] m does not cover "
                    f"the search volume's [{low[k]:g}, {high[k]:g}] m"
                )
        return None

    def _frames(self, time: float) -> list[tuple[int, float]]:
        """[(frame index, weight)] for episode time ``time`` s."""
        if not math.isfinite(time) or time < 0:
            raise ValueError(f"time must be a finite number of seconds >= 0 (got {time})")
        if len(self.t) == 1:
            return [(0, 1.0)]
        if time > self.duration + 1e-9:
            if not self.loop:
                raise _fail(
                    f"time {time:g} s is past the recording's {self.duration:g} s "
                    "(set loop = true or shorten search.budget)"
                )
            time = math.fmod(time, self.period)
        rec = self.t[0] + time
        if rec >= self.t[-1]:
            # past the last frame: it holds, or on a loop it leads back to frame 0
            if not self.loop:
                return [(len(self.t) - 1, 1.0)]
            frac = (rec - self.t[-1]) / (self.period - self.duration)
            if self.time_interpolation == "nearest":
                return [(0 if frac >= 0.5 else len(self.t) - 1, 1.0)]
            return [(len(self.t) - 1, 1.0 - frac), (0, frac)]
        i = int(np.searchsorted(self.t, rec, side="right")) - 1
        frac = (rec - self.t[i]) / (self.t[i + 1] - self.t[i])
        if self.time_interpolation == "nearest":
            return [(i + 1 if frac >= 0.5 else i, 1.0)]
        return [(i, 1.0 - frac), (i + 1, frac)]

    @staticmethod
    def _cells(coords: np.ndarray, v: np.ndarray, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Lower cell index (K,) and fraction (K,) of values ``v`` along one axis."""
        bad = ~((v >= coords[0] - 1e-9) & (v <= coords[-1] + 1e-9))
        if np.any(bad):
            raise _fail(
                f"position {name} = {v[bad][0]:g} m is outside the recording's grid "
                f"[{coords[0]:g}, {coords[-1]:g}] m"
            )
        i = np.clip(np.searchsorted(coords, v, side="right") - 1, 0, len(coords) - 2)
        frac = np.clip((v - coords[i]) / (coords[i + 1] - coords[i]), 0.0, 1.0)
        return i, frac

    def field(self, positions: np.ndarray, time: float) -> np.ndarray:
        """(K,) concentrations (g/m³) at (K, 3) positions at episode ``time`` s."""
        p = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        ix, fx = self._cells(self.x, p[:, 0], "x")
        iy, fy = self._cells(self.y, p[:, 1], "y")
        if self.z is not None:
            iz, fz = self._cells(self.z, p[:, 2], "z")
        out = np.zeros(len(p))
        for frame, w in self._frames(time):
            if w == 0.0:
                continue
            f = self.values[frame]
            for dy, wy in ((0, 1.0 - fy), (1, fy)):
                for dx, wx in ((0, 1.0 - fx), (1, fx)):
                    if self.z is None:
                        out += w * wy * wx * f[iy + dy, ix + dx]
                    else:
                        for dz, wz in ((0, 1.0 - fz), (1, fz)):
                            out += w * wy * wx * wz * f[iy + dy, ix + dx, iz + dz]
        return out

    def concentration(self, position: np.ndarray, time: float) -> float:
        return float(self.field(np.reshape(position, (1, 3)), time)[0])


# --- files ------------------------------------------------------------------------------------


def load_recording(
    path: str | Path, time_interpolation: str = "linear", loop: bool = False
) -> tuple[PlaybackTruth, np.ndarray | None]:
    """(truth, recorded source location (3,) or None) from a ``.npy`` (+ ``.json``) or ``.h5``."""
    path = Path(path)
    if not path.is_file():
        raise _fail(f"no such file {str(path)!r}")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        meta_path = path.with_suffix(".json")
        if not meta_path.is_file():
            raise _fail(f"{path.name} needs its metadata in {meta_path.name} (t, x, y, optional z)")
        try:
            check_npy(path, "truth.model.file")  # its declared shape, before it is read
            arr = np.load(path, allow_pickle=False)
            meta = json.loads(read_text(meta_path, "truth.model.file"))
        except DceeInputError:
            raise
        except (OSError, ValueError, RecursionError) as exc:
            raise _fail(f"cannot read {path.name} or {meta_path.name}: {exc}") from None
        if not isinstance(meta, dict):
            raise _fail(f"{meta_path.name} must hold a JSON object")
    elif suffix in (".h5", ".hdf5"):
        h5py = _h5py(_fail)
        try:
            with h5py.File(path, "r") as h5:
                if not isinstance(h5.get("concentration"), h5py.Dataset):
                    raise _fail(f"{path.name} has no 'concentration' dataset")
                names = [k for k in ("concentration", "t", "x", "y", "z") if k in h5]
                for k in names:  # declared shapes, before anything is read
                    if not isinstance(h5[k], h5py.Dataset):
                        raise _fail(f"{path.name}: {k!r} is not a dataset")
                    check_declared("truth.model.file", f"{path.name}: dataset {k!r}", h5[k].shape)
                arr = np.asarray(h5["concentration"][...])
                meta = {k: np.asarray(h5[k][...]) for k in names[1:]}
                if "source" in h5.attrs:
                    meta["source"] = np.asarray(h5.attrs["source"])
        except DceeInputError:
            raise
        except (OSError, ValueError, TypeError, KeyError, RuntimeError) as exc:
            # h5py reports a corrupt file as any of these
            first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise _fail(f"cannot read {path.name} as HDF5: {first}") from None
    else:
        raise _fail(
            f"unsupported recording {path.name!r}: use .npy (with .json), .h5 or CF NetCDF (.nc)"
        )
    if arr.ndim == 3 and "z" in meta and np.ndim(meta["z"]) == 0:
        meta.pop("z")  # a planar recording's height (recording_layout), not a grid axis
    missing = [k for k in ("t", "x", "y") if k not in meta]
    if arr.ndim == 4 and "z" not in meta:
        missing.append("z")
    if missing:
        raise _fail(f"{path.name}: missing metadata {', '.join(missing)}")
    truth = PlaybackTruth(
        arr, meta["t"], meta["x"], meta["y"], meta.get("z"), time_interpolation, loop
    )
    source = meta.get("source")
    if source is not None:
        source = np.asarray(source, dtype=np.float64)
        if source.shape != (3,) or not np.all(np.isfinite(source)):
            raise _fail(f"{path.name}: metadata 'source' must be 3 finite numbers (m)")
    return truth, source


def load_cf_recording(
    path: str | Path, time_interpolation: str = "linear", loop: bool = False, **mapping: Any
) -> tuple[PlaybackTruth, np.ndarray | None]:
    """(truth, recorded source (3,) m or None) from a CF-convention NetCDF/HDF5 recording made
    by others; ``mapping`` (variable, axes, units, molar_mass, temperature, pressure) goes to
    :func:`dcee.recordings.cf.read_cf_recording`."""
    rec = read_cf_recording(path, **mapping)
    truth = PlaybackTruth(
        rec["concentration"], rec["t"], rec["x"], rec["y"], rec["z"], time_interpolation, loop
    )
    return truth, rec["source"]


def save_recording(
    path: str | Path,
    concentration: np.ndarray,
    t: np.ndarray,
    x: np.ndarray,
    y: np.ndarray,
    z: np.ndarray | None = None,
    source: np.ndarray | None = None,
) -> None:
    """Write a recording that :func:`load_recording` reads (format by suffix: .npy or .h5)."""
    path = Path(path)
    meta = {"t": t, "x": x, "y": y} | ({"z": z} if z is not None else {})
    if path.suffix.lower() == ".npy":
        np.save(path, np.asarray(concentration, dtype=np.float64))
        doc = {k: np.asarray(v, dtype=np.float64).tolist() for k, v in meta.items()}
        if source is not None:
            doc["source"] = np.asarray(source, dtype=np.float64).tolist()
        path.with_suffix(".json").write_text(json.dumps(doc), encoding="utf-8")
    elif path.suffix.lower() in (".h5", ".hdf5"):
        h5py = _h5py(lambda msg: DceeInputError("recording", msg))
        with h5py.File(path, "w") as h5:
            h5.create_dataset("concentration", data=np.asarray(concentration, dtype=np.float64))
            for k, v in meta.items():
                h5.create_dataset(k, data=np.asarray(v, dtype=np.float64))
            if source is not None:
                h5.attrs["source"] = np.asarray(source, dtype=np.float64)
    else:
        raise ValueError(f"unsupported recording suffix {path.suffix!r}: use .npy or .h5")


def _h5py(fail: Any) -> Any:
    """h5py, an optional dependency (extra ``hdf5``): only HDF5 recordings need it."""
    try:
        import h5py
    except ImportError:
        raise fail("HDF5 recordings need h5py: pip install 'dcee[hdf5]' (or use .npy)") from None
    return h5py


@register_truth("playback")
def playback_truth(scenario: Scenario, seed: int) -> PlaybackTruth:
    """The recording named by ``truth.model.file``, checked against the scenario: it must cover
    the search area, agree on the source and last the budget (unless looped)."""
    spec = scenario.truth.model
    theta = scenario.truth_theta()
    low, high = np.array(scenario.volume.low), np.array(scenario.volume.high)
    if is_cf(spec.file, spec.variable, spec.axes):
        truth, source = load_cf_recording(
            spec.file,
            spec.time_interpolation,
            spec.loop,
            variable=spec.variable,
            axes=dict(spec.axes),
            units=spec.units,
            molar_mass=spec.molar_mass,
            temperature=spec.temperature,
            pressure=spec.pressure,
        )
    else:
        truth, source = load_recording(spec.file, spec.time_interpolation, spec.loop)
    problem = truth.covers(low, high)
    if problem:
        raise _fail(problem)
    if source is not None and not np.allclose(source, theta[:3], atol=1e-6):
        raise _fail(
            f"the recording's source {tuple(source)} differs from the scenario's truth "
            f"x, y, z {tuple(theta[:3])}"
        )
    budget = scenario.search.budget
    if not spec.loop and budget > truth.duration + 1e-9 and len(truth.t) > 1:
        raise _fail(
            f"the recording lasts {truth.duration:g} s but search.budget is {budget:g} s "
            "(set loop = true or shorten the budget)"
        )
    return truth


__all__ = ["PlaybackTruth", "load_cf_recording", "load_recording", "save_recording"]
