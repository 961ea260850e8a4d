"""Recordings made by others: CF-convention NetCDF (or NetCDF-4/HDF5) read through xarray.

Wind-tunnel, CFD and field recordings come with their own variable names, axis order and units.
This reader (:func:`read_cf_recording`; :func:`dcee.simulation.playback.load_cf_recording`
turns its arrays into a truth) finds what
:class:`~dcee.simulation.playback.PlaybackTruth` needs by the CF conventions and converts it
to dcee's units (g/m³, s, m), so a recording replays with one
``--set 'truth.model = {file = "plume.nc"}'``:

* **Concentration variable**: ``variable`` if given; else the one data variable with three or
  four dimensions whose ``units`` are a concentration (below); else the only variable with three
  or four dimensions.
* **Axes**: each dimension of that variable is the time, x, y or z axis by, in order, the
  scenario's ``axes`` mapping (``{t = "time", x = "easting", …}``), its coordinate's ``axis``
  attribute (T, X, Y, Z), its ``standard_name`` (``time``, ``projection_x_coordinate``,
  ``projection_y_coordinate``, ``height``, ``altitude``, …), or a conventional name (``t``,
  ``time``, ``x``, ``y``, ``z``, ``height``, …). The array is transposed to (t, y, x[, z]); a
  decreasing axis is flipped.
* **Units**: time in s, ms, min, h or d (``"seconds since 2024-01-01"`` included: episode time 0
  is the first frame); lengths in m, cm, mm, km or ft; concentration as a mass density (g/m³,
  kg/m³, mg/m³, µg/m³ in any CF spelling: ``kg m-3``, ``kg/m^3``, …) or a mixing ratio (ppm,
  ppb, ppt, mol/mol, ``1e-6``), which needs ``molar_mass`` (g/mol) and is converted at
  ``temperature`` (K) and ``pressure`` (Pa) by the ideal gas law. ``units`` in the scenario
  overrides the file's.
* **Source** (optional): a global attribute ``source_location`` (x, y, z in the x/y/z axes'
  units) is checked against the scenario's truth.

Every problem (no such variable, a missing axis, unknown units, NaN or missing values, negative
concentrations, a grid that does not cover the search area) is one :class:`DceeInputError` line
naming the field, raised before any search starts.
"""

from __future__ import annotations

import gc
import re
import sys
from pathlib import Path
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.limits import check_declared

FIELD = "truth.model.file"
SUFFIXES = (".nc", ".nc4", ".netcdf", ".cdf")
"""Recordings read by this module (``.h5`` files are dcee's own layout unless ``variable`` or
``axes`` is given)."""

GAS_CONSTANT = 8.314462618  # J/(mol K)

TIME_SECONDS = {
    "s": 1.0, "sec": 1.0, "secs": 1.0, "second": 1.0, "seconds": 1.0,
    "ms": 1e-3, "millisecond": 1e-3, "milliseconds": 1e-3,
    "min": 60.0, "mins": 60.0, "minute": 60.0, "minutes": 60.0,
    "h": 3600.0, "hr": 3600.0, "hrs": 3600.0, "hour": 3600.0, "hours": 3600.0,
    "d": 86400.0, "day": 86400.0, "days": 86400.0,
}  # fmt: skip
LENGTH_METRES = {
    "m": 1.0, "metre": 1.0, "metres": 1.0, "meter": 1.0, "meters": 1.0,
    "cm": 0.01, "mm": 0.001, "km": 1000.0, "ft": 0.3048, "feet": 0.3048,
}  # fmt: skip
MASS_GRAMS = {"kg": 1000.0, "g": 1.0, "mg": 1e-3, "ug": 1e-6, "µg": 1e-6, "μg": 1e-6, "ng": 1e-9}
MIXING_RATIOS = {
    "ppm": 1e-6, "ppmv": 1e-6, "ppb": 1e-9, "ppbv": 1e-9, "ppt": 1e-12, "pptv": 1e-12,
    "mol/mol": 1.0, "mol mol-1": 1.0, "mol mol^-1": 1.0, "1": 1.0, "1e-6": 1e-6, "1e-9": 1e-9,
}  # fmt: skip

STANDARD_NAMES = {
    "t": ("time",),
    "x": ("projection_x_coordinate", "grid_longitude", "x"),
    "y": ("projection_y_coordinate", "grid_latitude", "y"),
    "z": ("height", "altitude", "height_above_ground", "height_above_ground_level", "z"),
}
NAMES = {
    "t": ("t", "time", "times"),
    "x": ("x", "xc", "x_m", "easting", "east"),
    "y": ("y", "yc", "y_m", "northing", "north"),
    "z": ("z", "zc", "z_m", "height", "altitude", "level", "elevation"),
}


def _fail(msg: str) -> DceeInputError:
    return DceeInputError(FIELD, msg)


def concentration_factor(
    units: str, molar_mass: float | None, temperature: float, pressure: float
) -> float:
    """Factor turning a concentration in ``units`` into g/m³ (ideal gas for mixing ratios)."""
    u = units.strip().replace("**", "^").replace("µ", "u").replace("μ", "u")
    ratio = MIXING_RATIOS.get(u.lower())
    if ratio is not None:
        if molar_mass is None:
            raise _fail(
                f"concentration units {units!r} are a mixing ratio: give the gas's molar_mass "
                "(g/mol) in truth.model to convert it to g/m³"
            )
        return ratio * pressure * molar_mass / (GAS_CONSTANT * temperature)
    match = re.fullmatch(r"(kg|g|mg|ug|ng)\s*(?:/\s*m\^?3|m-3|m\^-3|\s+m-3|\s+m\^-3)", u)
    if match is None:
        raise _fail(
            f"unknown concentration units {units!r}: use a mass density (g/m3, kg m-3, mg/m3, "
            "ug/m3) or a mixing ratio (ppm, ppb, mol/mol), or set truth.model.units"
        )
    return MASS_GRAMS[match.group(1)]


def _scale(units: str | None, table: dict[str, float], what: str, name: str) -> float:
    if units is None:
        raise _fail(f"axis {name!r} ({what}) has no units attribute")
    key = units.split(" since ")[0].strip().lower() if what == "time" else units.strip().lower()
    if key not in table:
        allowed = ", ".join(sorted({k for k in table if len(k) <= 3}))
        raise _fail(f"axis {name!r} has unknown {what} units {units!r} (allowed: {allowed}, …)")
    return table[key]


def _open(path: Path) -> Any:
    try:
        import xarray as xr
    except ImportError:
        raise _fail("NetCDF recordings need xarray: pip install 'dcee[netcdf]'") from None
    # a file h5netcdf fails to open leaves a half-made object whose finaliser prints a traceback
    # of its own ("Exception ignored in ... close") when the failure's frames are let go: not
    # the user's to read, so that finaliser runs, silenced, before the one-line error
    hook = sys.unraisablehook
    sys.unraisablehook = _ignore
    try:
        try:
            return xr.open_dataset(path, decode_times=False, mask_and_scale=True)
        except Exception as exc:  # xarray raises many kinds (ValueError, OSError, engine errors)
            first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        gc.collect()
    finally:
        sys.unraisablehook = hook
    raise _fail(f"cannot read {path.name} as NetCDF: {first}")


def _ignore(unraisable: object) -> None:
    """An unraisable-exception hook that prints nothing (:func:`_open`)."""


def _is_concentration(units: object) -> bool:
    if not isinstance(units, str):
        return False
    try:
        concentration_factor(units, 1.0, 293.15, 101325.0)
    except DceeInputError:
        return False
    return units.strip() != "1"


def _data_variable(ds: Any, name: str | None, path: Path) -> Any:
    if name is not None:
        if name not in ds.data_vars:
            raise _fail(
                f"{path.name} has no variable {name!r} (it has {', '.join(map(str, ds.data_vars))})"
            )
        return ds[name]
    fields = [v for v in ds.data_vars.values() if v.ndim in (3, 4)]
    dense = [v for v in fields if _is_concentration(v.attrs.get("units"))]
    if len(dense) == 1:
        return dense[0]
    if len(fields) == 1:
        return fields[0]
    names = ", ".join(str(v.name) for v in (dense or fields)) or "none"
    raise _fail(
        f"{path.name}: cannot tell which variable is the concentration (3-D or 4-D variables: "
        f"{names}); set truth.model.variable"
    )


def _axis_of(ds: Any, dim: str, mapping: dict[str, str]) -> str | None:
    for axis, name in mapping.items():
        if name == dim:
            return axis
    attrs = ds[dim].attrs if dim in ds.variables else {}
    cf_axis = str(attrs.get("axis", "")).upper()
    if cf_axis in ("T", "X", "Y", "Z"):
        return cf_axis.lower()
    standard = str(attrs.get("standard_name", "")).lower()
    for axis, names in STANDARD_NAMES.items():
        if standard in names:
            return axis
    for axis, names in NAMES.items():
        if dim.lower() in names:
            return axis
    return None


def cf_layout(
    path: str | Path, variable: str | None = None, axes: dict[str, str] | None = None
) -> tuple[bool, float | None]:
    """(planar, plane height in m or None) of a CF recording without reading its values: planar
    when the concentration variable has no z axis; the plane's height from a scalar (0-d)
    coordinate with axis Z or a height standard_name (CF's way of saying which level a 2-D
    slice holds), in metres."""
    path = Path(path)
    if not path.is_file():
        raise _fail(f"no such file {str(path)!r}")
    mapping = dict(axes or {})
    with _open(path) as ds:
        var = _data_variable(ds, variable, path)
        dims = [_axis_of(ds, str(dim), mapping) for dim in var.dims]
        if "z" in dims:
            return False, None
        for name in var.coords:
            coord = ds[name]
            if coord.ndim != 0 or _axis_of(ds, str(name), {}) != "z":
                continue
            scale = _scale(coord.attrs.get("units"), LENGTH_METRES, "length", str(name))
            height = float(np.asarray(coord.values, dtype=np.float64)) * scale
            if np.isfinite(height):
                return True, height
        return True, None


def read_cf_recording(
    path: str | Path,
    variable: str | None = None,
    axes: dict[str, str] | None = None,
    units: str | None = None,
    molar_mass: float | None = None,
    temperature: float = 293.15,
    pressure: float = 101325.0,
) -> dict[str, np.ndarray | None]:
    """The arrays of a CF-style NetCDF/HDF5 recording in dcee's units (module doc):
    ``concentration`` (T, ny, nx[, nz]) g/m³, ``t`` (s from the first frame), ``x``, ``y``, ``z``
    (m, increasing; ``z`` None for a 2-D recording) and ``source`` ((3,) m or None)."""
    path = Path(path)
    if not path.is_file():
        raise _fail(f"no such file {str(path)!r}")
    mapping = dict(axes or {})
    bad = sorted(set(mapping) - {"t", "x", "y", "z"})
    if bad:
        raise DceeInputError("truth.model.axes", f"keys must be t, x, y, z (got {bad[0]!r})")
    with _open(path) as ds:
        var = _data_variable(ds, variable, path)
        found: dict[str, str] = {}
        for dim in map(str, var.dims):
            axis = _axis_of(ds, dim, mapping)
            if axis is None:
                raise _fail(
                    f"{path.name}: cannot tell which axis dimension {dim!r} of {var.name!r} is "
                    "(no axis/standard_name attribute); map it in truth.model.axes"
                )
            if axis in found:
                raise _fail(f"{path.name}: dimensions {found[axis]!r} and {dim!r} are both {axis}")
            found[axis] = dim
        missing = [a for a in ("t", "x", "y") if a not in found]
        if missing:
            raise _fail(
                f"{path.name}: variable {var.name!r} has no {', '.join(missing)} axis "
                f"(dimensions {', '.join(map(str, var.dims))})"
            )
        order = ["t", "y", "x"] + (["z"] if "z" in found else [])
        check_declared(FIELD, f"{path.name}: variable {var.name!r}", var.shape)  # before reading
        for a in order:
            if found[a] in ds.variables:
                check_declared(FIELD, f"{path.name}: axis {found[a]!r}", ds[found[a]].shape)
        arr = np.asarray(var.transpose(*[found[a] for a in order]).values, dtype=np.float64)
        coords = {}
        for a in order:
            dim = found[a]
            if dim not in ds.variables:
                raise _fail(f"{path.name}: axis {a} ({dim!r}) has no coordinate values")
            values = np.asarray(ds[dim].values, dtype=np.float64)
            what = "time" if a == "t" else "length"
            table = TIME_SECONDS if a == "t" else LENGTH_METRES
            values = values * _scale(ds[dim].attrs.get("units"), table, what, dim)
            if values.size > 1 and np.all(np.diff(values) < 0):  # decreasing: flip
                values = values[::-1]
                arr = np.flip(arr, axis=order.index(a))
            coords[a] = values
        conc_units = units if units is not None else var.attrs.get("units")
        if conc_units is None:
            raise _fail(
                f"{path.name}: variable {var.name!r} has no units attribute; set truth.model.units"
            )
        factor = concentration_factor(str(conc_units), molar_mass, temperature, pressure)
        nan = int(np.count_nonzero(~np.isfinite(arr)))
        if nan:
            raise _fail(
                f"{path.name}: {nan} of {arr.size} values of {var.name!r} are NaN or missing "
                "(fill them before replaying)"
            )
        if np.any(arr < 0):
            raise _fail(
                f"{path.name}: {var.name!r} has negative concentrations (min {arr.min():g})"
            )
        source = ds.attrs.get("source_location")
        if source is not None:
            source = np.asarray(source, dtype=np.float64).ravel()
            if source.shape != (3,) or not np.all(np.isfinite(source)):
                raise _fail(f"{path.name}: attribute source_location must be 3 finite numbers")
            xs = _scale(ds[found["x"]].attrs.get("units"), LENGTH_METRES, "length", found["x"])
            source = source * xs
    return {
        "concentration": arr * factor,
        "t": coords["t"] - coords["t"][0],
        "x": coords["x"],
        "y": coords["y"],
        "z": coords.get("z"),
        "source": source,
    }


__all__ = ["cf_layout", "concentration_factor", "read_cf_recording"]
