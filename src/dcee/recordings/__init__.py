"""Plume recordings on disk: what a file holds, read without the simulation that replays it.

:mod:`dcee.recordings.cf` reads CF-convention NetCDF recordings made by others;
:func:`recording_layout` tells, from a file's header alone, whether a recording is planar
(time × y × x: one horizontal plane, the same at every altitude) and which height that plane
holds where the file says. The scenario needs this before any search starts (a planar
recording fixes the agent's altitude and makes the search planar, docs/scenarios.md); the
arrays themselves are loaded by :mod:`dcee.simulation.playback`.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from dcee.errors import DceeInputError
from dcee.limits import check_npy, read_text
from dcee.recordings.cf import SUFFIXES, cf_layout

FIELD = "truth.model.file"


def is_cf(file: str | Path, variable: str | None = None, axes: dict | None = None) -> bool:
    """Whether a recording is read as CF NetCDF (by suffix, or because a variable or axis
    mapping was given) rather than as dcee's own .npy/.h5 layout."""
    return Path(file).suffix.lower() in SUFFIXES or variable is not None or bool(axes)


def recording_layout(
    file: str | Path, variable: str | None = None, axes: dict | None = None
) -> tuple[bool, float | None]:
    """(planar, plane height m or None) of a recording, from its header: planar when the
    concentration array has no z axis (3 dimensions: t, y, x). The plane's height comes from
    the metadata where given: a scalar ``z`` in a .npy's JSON or a .h5's ``z`` attribute, or a
    CF scalar height coordinate."""
    path = Path(file)
    if not path.is_file():
        raise DceeInputError(FIELD, f"no such file {str(path)!r}")
    if is_cf(path, variable, axes):
        return cf_layout(path, variable, axes)
    suffix = path.suffix.lower()
    plane: object = None
    try:
        if suffix == ".npy":
            ndim = len(check_npy(path, FIELD))  # the header alone
            meta_path = path.with_suffix(".json")
            if meta_path.is_file():
                meta = json.loads(read_text(meta_path, FIELD))
                plane = meta.get("z") if isinstance(meta, dict) else None
        elif suffix in (".h5", ".hdf5"):
            import h5py

            with h5py.File(path, "r") as h5:
                if not isinstance(h5.get("concentration"), h5py.Dataset):
                    raise DceeInputError(FIELD, f"{path.name} has no 'concentration' dataset")
                ndim = h5["concentration"].ndim
                plane = h5.attrs.get("z")
        else:
            raise DceeInputError(
                FIELD,
                f"unsupported recording {path.name!r}: use .npy (with .json), .h5 or CF "
                "NetCDF (.nc)",
            )
    except DceeInputError:
        raise  # already one line naming the field (a ValueError: not to be wrapped below)
    except ImportError:
        raise DceeInputError(
            FIELD, "HDF5 recordings need h5py: pip install 'dcee[hdf5]' (or use .npy)"
        ) from None
    except (OSError, ValueError, TypeError, KeyError, RuntimeError, RecursionError) as exc:
        # h5py reports a corrupt file as any of these; JSON nested too deep: RecursionError
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise DceeInputError(FIELD, f"cannot read {path.name}: {first}") from None
    if ndim != 3:
        return False, None
    try:
        height = float(np.asarray(plane, dtype=np.float64)) if plane is not None else None
    except (TypeError, ValueError):
        height = None  # a list: z of a 3-D grid, not a plane's height
    return True, height if height is not None and np.isfinite(height) else None


__all__ = ["is_cf", "recording_layout"]
