"""Scenario files: find a scenario by built-in name or TOML path and validate it, write one back
as TOML (``dcee show``), and read the command line's ``--set`` and ``--truth`` values."""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path
from typing import Any

from dcee.errors import DceeInputError
from dcee.scenarios.builtin import (
    RANDOM_FAMILIES,
    builtin_scenarios,
    random_family_configuration,
    random_family_name,
)
from dcee.scenarios.defaults import DEFAULTS
from dcee.scenarios.gaden_room import gaden_room_configuration, is_gaden_folder
from dcee.scenarios.geo_area import SITES, area_configuration, expand_area, packaged_site
from dcee.scenarios.schema import Scenario, validate_scenario
from dcee.stopping import DEFAULT_STOP_SHARE


def expand_names(names: list[str]) -> list[str]:
    """Scenario names with ranges expanded: ``random:1-3`` -> random:1, random:2, random:3 (any
    ``family:A-B`` with integers A <= B); every other name as given."""
    out: list[str] = []
    for name in names:
        family, _, rest = name.partition(":")
        a, dash, b = rest.partition("-")
        if dash and a.isdigit() and b.isdigit() and int(a) <= int(b):
            out += [f"{family}:{k}" for k in range(int(a), int(b) + 1)]
        else:
            out.append(name)
    return out


def load_scenario(name_or_path: str) -> Scenario:
    """A built-in (``paper:3``, ``lab:upwind``, ``random:17``) or a TOML file by path."""
    builtins = builtin_scenarios()
    if name_or_path in builtins:
        return validate_scenario(builtins[name_or_path])
    try:
        family = random_family_name(name_or_path)
    except ValueError as exc:
        raise DceeInputError("scenario", str(exc)) from None
    if family is not None:
        return validate_scenario(random_family_configuration(*family))
    if name_or_path.startswith("area:"):
        return validate_scenario(area_configuration(packaged_site(name_or_path[5:])))
    path = Path(name_or_path)
    if is_gaden_folder(path):
        return validate_scenario(gaden_room_configuration(path))
    if path.suffix.lower() in (".geojson", ".json") and path.is_file():
        return validate_scenario(area_configuration(path))
    if not path.suffix == ".toml" and ":" in name_or_path:
        families = ", ".join(f"{f}:K" for f in RANDOM_FAMILIES)
        sites = ", ".join(f"area:{p.stem}" for p in sorted(SITES.glob("*.geojson")))
        raise DceeInputError(
            "scenario",
            f"unknown built-in {name_or_path!r}; choose one of {', '.join(builtins)}, "
            f"{families} (K an integer >= 1), {sites}, a TOML file, a GeoJSON site or a GADEN "
            "simulation folder",
        )
    if not path.is_file():
        raise DceeInputError("scenario", f"no such file {str(path)!r} and no such built-in")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise DceeInputError("scenario", f"malformed TOML in {path}: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DceeInputError("scenario", f"cannot read {path}: {exc}") from None
    data.setdefault("name", path.stem)
    _resolve_recording(data, path.parent)
    return validate_scenario(expand_area(data, path.parent))


def _resolve_recording(data: dict, base: Path) -> None:
    """A playback file named in a scenario file is relative to that file, not to the cwd."""
    model = data.get("truth", {}).get("model") if isinstance(data.get("truth"), dict) else None
    if isinstance(model, dict) and isinstance(model.get("file"), str):
        file = Path(model["file"]).expanduser()
        if not file.is_absolute():
            model["file"] = str((base / file).resolve())


def truth_choice(value: str) -> str | dict[str, str]:
    """The ``truth.model`` a ``--truth`` option names: "isotropic", "filament", "puffs", "lbm",
    "lbm3d", the path of a recording (``.npy``/``.h5``/``.nc``) or of a GADEN simulation folder,
    made absolute so that it means the same file wherever the
    configuration is used later."""
    if value in ("isotropic", "filament", "puffs", "lbm", "lbm3d"):
        return value
    path = Path(value).expanduser()
    if path.is_dir():
        if not is_gaden_folder(path):
            raise DceeInputError(
                "truth",
                f"{value!r} is a folder but not a GADEN simulation (it needs "
                "OccupancyGrid3D.csv and result/iteration_<k> files)",
            )
        return {"kind": "gaden", "folder": str(path.resolve())}
    if path.suffix.lower() not in (".npy", ".h5", ".hdf5", ".nc", ".nc4", ".netcdf", ".cdf"):
        raise DceeInputError(
            "truth",
            f"must be isotropic, filament, puffs, lbm, lbm3d, a .npy/.h5/.nc recording or a "
            f"GADEN simulation folder "
            f"(got {value!r})",
        )
    if not path.is_file():
        raise DceeInputError("truth", f"no such recording {value!r}")
    return {"file": str(path.resolve())}


def parse_setting(text: str) -> tuple[str, Any]:
    """``"estimator.log_sd=0.8"`` → ("estimator.log_sd", 0.8): a dotted scenario path and a
    TOML value (a bare word that is not TOML is taken as a string)."""
    path, sep, raw = text.partition("=")
    path = path.strip()
    if not sep or not path or any(not part for part in path.split(".")):
        raise DceeInputError("set", f"must look like section.field=value, got {text!r}")
    try:
        value = tomllib.loads(f"v = {raw.strip()}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw.strip()
    return path, value


def _is_default(scenario: Scenario, section: str, key: str, value: object) -> bool:
    """Whether ``section.key`` holds its class default (a built-in scenario's own value, e.g.
    the lab's fitted log-sd, is not the measured default and gets no provenance line)."""
    model = type(getattr(scenario, section))
    field = model.model_fields.get(key)
    return field is not None and field.default == value


def to_toml(scenario: Scenario, provenance: bool = True) -> str:
    """The scenario as a TOML file that :func:`dcee.scenarios.load_scenario` reads back to an
    equal scenario (``dcee show NAME --format toml > my.toml``): every resolved setting, so the
    file is a complete record; optional values left unset (None), whose default depends on the
    truth or the likelihood, appear as comments with the value they resolve to. With
    ``provenance``, a comment under each measured default says what it was chosen on
    (:data:`dcee.scenarios.defaults.DEFAULTS`)."""
    data = scenario.model_dump(mode="json", exclude_none=True)
    # settings left unset follow the truth or the likelihood: shown as comments with the value
    # this scenario resolves them to, so the file reads back with them still unset
    resolved = scenario.resolution_map()
    unread = scenario.unread_settings()
    # unset with no single resolved value: what unset means, in words
    unset = {
        ("search", "stop_spread"): (
            f"unset: on a robot {DEFAULT_STOP_SHARE:g} x acquired_rmse = "
            f"{DEFAULT_STOP_SHARE * scenario.search.acquired_rmse:g} m, in a simulation never"
        ),
        ("world", "map"): "unset: no occupancy-grid map",
        ("world", "area"): "unset: a local frame only, no map in geographic coordinates",
        ("world", "frame"): "unset: written when world.area is read",
        ("agent", "min_altitude"): (
            f"unset: the area's floor, {scenario.volume.low[2]:g} m; the agent flies no lower"
        ),
        ("estimator", "count_prior"): "unset: every count 0 … max_sources equally likely",
        ("estimator", "wall_lifetime"): "unset: no decay, a conserved gas (the wall-aware plume)",
    }
    lines = [f"# dcee scenario {scenario.name}"]
    tables = []
    for key, value in data.items():
        if isinstance(value, dict):
            tables.append((key, value))
        else:
            lines.append(f"{key} = {_toml_value(value)}")
    for key, table in tables:
        lines.append("")
        lines.append(f"[{key}]")
        for k, v in table.items():
            lines.append(f"{_toml_key(k)} = {_toml_value(v)}")
            if provenance and (key, k) in DEFAULTS and _is_default(scenario, key, k, v):
                lines.append(f"# ^ default, {DEFAULTS[key, k].line()}")
            if k == "phi" and key in ("truth", "prior"):
                lines.append(_bearing_comment(v))
        for (section, k), v in resolved.items():
            if section == key and k not in table:
                if (key, k) in unread:
                    lines.append(
                        f"# {k} = {_toml_value(v)}  (unset; not read with {unread[key, k]})"
                    )
                    continue
                lines.append(f"# {k} = {_toml_value(v)}  (unset: the default for this scenario)")
                if provenance and (key, k) in DEFAULTS:
                    lines.append(f"# ^ {DEFAULTS[key, k].line()}")
        for (section, k), words in unset.items():
            if section == key and k not in table:
                lines.append(f"# {k} =  ({words})")
    return "\n".join(lines) + "\n"


def _bearing_comment(phi: Any) -> str:
    """The comment under a ``phi`` (°, counter-clockwise from east): the compass bearing it
    is, and how to write it as one (``wind_from``)."""
    from dcee.models.compass import bearing_from_phi, wind_from_words

    if isinstance(phi, dict):  # a prior: its centre or its range
        if phi.get("mean") is not None:
            return f"# ^ centred on {wind_from_words(phi['mean'])} (compass bearing)"
        lo, hi = phi.get("low"), phi.get("high")
        if lo is not None and hi is not None and hi - lo >= 360.0:
            return "# ^ wind from any direction (a uniform prior over the full circle)"
        if lo is not None and hi is not None:
            return (
                f"# ^ wind from bearings {bearing_from_phi(hi):g}° to {bearing_from_phi(lo):g}° "
                "clockwise (compass)"
            )
        return "# ^ phi: degrees counter-clockwise from east (x), where the wind comes from"
    bearing = bearing_from_phi(float(phi))
    return (
        f"# ^ {wind_from_words(float(phi))}: phi is counter-clockwise from east (x); "
        f"wind_from = {bearing:g} says the same as a compass bearing"
    )


def _toml_key(key: str) -> str:
    return key if key.replace("_", "").replace("-", "").isalnum() else json.dumps(key)


def _toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)  # a JSON string is a TOML basic string
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        inner = ", ".join(
            f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items() if v is not None
        )
        return "{ " + inner + " }" if inner else "{}"
    raise TypeError(f"cannot write {type(value).__name__} as TOML")
