"""Writing a state file (:mod:`dcee.state_file`): the object graph to JSON and arrays."""

from __future__ import annotations

import enum
import hashlib
import io
import json
import math
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from dcee.provenance import package_version
from dcee.state_file.layout import BIT_GENERATORS, DIGEST, HEADER, MAX_DEPTH, checksum


class _Encoder:
    def __init__(self) -> None:
        self.arrays: dict[str, np.ndarray] = {}
        self.seen: dict[int, int] = {}
        self.keep: list[Any] = []  # keeps encoded objects alive, so their ids stay unique

    def _ref(self, obj: Any) -> int | None:
        return self.seen.get(id(obj))

    def _new_ref(self, obj: Any) -> int:
        n = len(self.seen)
        self.seen[id(obj)] = n
        self.keep.append(obj)
        return n

    def encode(self, obj: Any, path: str, depth: int = 0) -> Any:
        if depth > MAX_DEPTH:
            raise TypeError(f"{path}: nested deeper than {MAX_DEPTH}")
        if obj is None or isinstance(obj, bool | str):
            return obj
        if isinstance(obj, enum.Enum):
            return {"enum": [_class_name(type(obj), path), self.encode(obj.value, path, depth)]}
        if isinstance(obj, int):
            return int(obj)
        if isinstance(obj, float):
            return obj if math.isfinite(obj) else {"float": repr(obj)}
        if isinstance(obj, np.generic):
            if obj.dtype.hasobject:
                raise TypeError(f"{path}: an object scalar cannot be saved")
            return {"scalar": [obj.dtype.str, self.encode(obj.item(), path, depth)]}
        if isinstance(obj, list):
            return [self.encode(v, f"{path}[{i}]", depth + 1) for i, v in enumerate(obj)]
        if isinstance(obj, tuple) and type(obj) is not tuple:
            if not hasattr(obj, "_fields"):
                raise TypeError(f"{path}: a tuple subclass {type(obj).__name__} cannot be saved")
            items = [self.encode(v, f"{path}[{i}]", depth + 1) for i, v in enumerate(obj)]
            return {"namedtuple": [_class_name(type(obj), path), items]}
        if isinstance(obj, tuple):
            return {"tuple": [self.encode(v, f"{path}[{i}]", depth + 1) for i, v in enumerate(obj)]}
        if isinstance(obj, set | frozenset):
            kind = "set" if isinstance(obj, set) else "frozenset"
            items = sorted(obj, key=repr)
            return {kind: [self.encode(v, path, depth + 1) for v in items]}
        if isinstance(obj, dict):
            return {
                "dict": [
                    [self.encode(k, path, depth + 1), self.encode(v, f"{path}[{k!r}]", depth + 1)]
                    for k, v in obj.items()
                ]
            }
        ref = self._ref(obj)
        if ref is not None:
            return {"ref": ref}
        if isinstance(obj, np.ndarray):
            if obj.dtype.hasobject:
                raise TypeError(f"{path}: an object array cannot be saved")
            n = self._new_ref(obj)
            name = f"a{len(self.arrays)}"
            self.arrays[name] = obj
            return {"array": [name, n]}
        if isinstance(obj, np.random.Generator):
            n = self._new_ref(obj)
            bit = obj.bit_generator
            kind = type(bit).__name__
            if kind not in BIT_GENERATORS:
                raise TypeError(f"{path}: bit generator {kind} cannot be saved")
            return {"rng": [kind, n, self.encode(bit.state, f"{path}.state", depth + 1)]}
        name = _class_name(type(obj), path)
        n = self._new_ref(obj)
        state = obj.__getstate__()
        return {"object": [name, n, self.encode(state, f"{path}.{name}", depth + 1)]}


def _class_name(cls: type, path: str) -> str:
    module = cls.__module__
    if not (module == "dcee" or module.startswith("dcee.")) or "<locals>" in cls.__qualname__:
        raise TypeError(
            f"{path}: a {module}.{cls.__qualname__} cannot be saved (only dcee's own classes, "
            "NumPy arrays and generators, numbers, strings and containers)"
        )
    return f"{module}:{cls.__qualname__}"


def write_state(
    path: Path, format_name: str, obj: Any, meta: dict[str, Any], code: dict[str, Any]
) -> None:
    """Write ``obj`` (module doc) to ``path`` as it is (the caller writes atomically). Raises
    TypeError naming the attribute that holds something that cannot be saved (a function, a
    foreign class)."""
    enc = _Encoder()
    state = enc.encode(obj, "state")
    header: dict[str, Any] = {
        "format": format_name,
        "dcee_version": package_version(),
        "code": code,
        "meta": meta,
        "arrays": {k: [a.dtype.str, list(a.shape)] for k, a in enc.arrays.items()},
        "state": state,
    }
    header["checksum"] = checksum(header, enc.arrays)
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_STORED) as zf:
        zf.writestr(_member(HEADER), json.dumps(header, allow_nan=False))
        for name, a in enc.arrays.items():
            buf = io.BytesIO()
            np.lib.format.write_array(buf, np.ascontiguousarray(a), allow_pickle=False)
            zf.writestr(_member(f"{name}.npy"), buf.getvalue())
        zf.comment = DIGEST + b"0" * 64
    data = bytearray(out.getvalue())
    data[-64:] = hashlib.sha256(data[:-64]).hexdigest().encode()
    Path(path).write_bytes(bytes(data))


def _member(name: str) -> zipfile.ZipInfo:
    """A zip entry with a fixed date (the same state, the same bytes)."""
    info = zipfile.ZipInfo(name, date_time=(2020, 1, 1, 0, 0, 0))
    info.compress_type = zipfile.ZIP_STORED
    return info
