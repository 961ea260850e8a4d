"""Find a scenario by built-in name or TOML path and validate it."""

from __future__ import annotations

import tomllib
from pathlib import Path

from dcee.errors import DceeInputError
from dcee.scenarios.builtin import builtin_scenarios, random_configuration, random_family_name
from dcee.scenarios.config import Scenario, validate_scenario


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
        return validate_scenario(
            random_configuration(family[1], random_start=family[0] == "random-start")
        )
    path = Path(name_or_path)
    if not path.suffix == ".toml" and ":" in name_or_path:
        raise DceeInputError(
            "scenario",
            f"unknown built-in {name_or_path!r}; choose one of {', '.join(builtins)}, "
            "random:K or random-start:K (K an integer >= 1)",
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
    return validate_scenario(data)


def _resolve_recording(data: dict, base: Path) -> None:
    """A playback file named in a scenario file is relative to that file, not to the cwd."""
    model = data.get("truth", {}).get("model") if isinstance(data.get("truth"), dict) else None
    if isinstance(model, dict) and isinstance(model.get("file"), str):
        file = Path(model["file"]).expanduser()
        if not file.is_absolute():
            model["file"] = str((base / file).resolve())
