"""Reading a state file (:mod:`dcee.state_file`) without trusting it: limits first, no pickle,
only dcee's own classes made."""

from __future__ import annotations

import enum
import hashlib
import importlib
import io
import json
import math
import re
import zipfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from dcee.errors import DceeInputError
from dcee.provenance import package_version
from dcee.state_file.layout import (
    BIT_GENERATORS,
    DIGEST,
    HEADER,
    MAX_ARRAY_BYTES,
    MAX_DEPTH,
    MAX_HEADER_BYTES,
    checksum,
)


def _read_array(zf: zipfile.ZipFile, name: str, fail: Callable[[str], DceeInputError]) -> Any:
    member = f"{name}.npy"
    try:
        info = zf.getinfo(member)
    except KeyError:
        raise fail(f"array {name} is missing") from None
    with zf.open(info) as fh:
        try:
            version = np.lib.format.read_magic(fh)
            if version == (1, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_1_0(fh)
            elif version == (2, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_2_0(fh)
            else:
                raise ValueError(f"npy version {version}")
        except zipfile.BadZipFile:
            raise
        except Exception as exc:  # numpy parses the header text: any failure is a bad header
            raise fail(f"array {name} has no valid .npy header ({type(exc).__name__})") from None
        if dtype.hasobject:
            raise fail(f"array {name} holds Python objects (refused)")
        count = math.prod(shape)
        nbytes = count * dtype.itemsize
        if nbytes > MAX_ARRAY_BYTES or nbytes > info.file_size:
            raise fail(
                f"array {name} declares {shape} of {dtype} ({nbytes} bytes), more than its "
                f"entry holds ({info.file_size}) or the limit ({MAX_ARRAY_BYTES})"
            )
        data = fh.read(nbytes)
    if len(data) != nbytes:
        raise fail(f"array {name} is truncated")
    out = np.frombuffer(data, dtype=dtype).copy()
    return out.reshape(shape, order="F" if fortran else "C")


class _Decoder:
    def __init__(self, arrays: dict[str, np.ndarray], fail: Callable[[str], DceeInputError]):
        self.arrays = arrays
        self.fail = fail
        self.refs: dict[int, Any] = {}

    def _register(self, n: Any, obj: Any) -> None:
        if not isinstance(n, int) or isinstance(n, bool) or n in self.refs:
            raise self.fail(f"bad object id {n!r}")
        self.refs[n] = obj

    def decode(self, node: Any, depth: int = 0) -> Any:
        if depth > MAX_DEPTH:
            raise self.fail(f"the state is nested deeper than {MAX_DEPTH}")
        if node is None or isinstance(node, bool | int | float | str):
            return node
        if isinstance(node, list):
            return [self.decode(v, depth + 1) for v in node]
        if not (isinstance(node, dict) and len(node) == 1):
            raise self.fail(f"unreadable state entry {str(node)[:60]!r}")
        ((tag, value),) = node.items()
        return self._tagged(tag, value, depth)

    def _pairs(self, value: Any, size: int, tag: str) -> list:
        if not (isinstance(value, list) and len(value) == size):
            raise self.fail(f"an entry tagged {tag!r} must be a list of {size}")
        return value

    def _tagged(self, tag: str, value: Any, depth: int) -> Any:
        if tag == "dict":
            if not isinstance(value, list):
                raise self.fail("a 'dict' entry must be a list of pairs")
            out = {}
            for pair in value:
                k, v = self._pairs(pair, 2, "dict")
                key = self.decode(k, depth + 1)
                try:
                    out[key] = self.decode(v, depth + 1)
                except TypeError:
                    raise self.fail(f"unhashable key {str(k)[:40]}") from None
            return out
        if tag in ("tuple", "set", "frozenset"):
            if not isinstance(value, list):
                raise self.fail(f"a {tag!r} entry must be a list")
            items = [self.decode(v, depth + 1) for v in value]
            try:
                return {"tuple": tuple, "set": set, "frozenset": frozenset}[tag](items)
            except TypeError:
                raise self.fail(f"a {tag} of unhashable items") from None
        if tag == "float":
            if value not in ("nan", "inf", "-inf"):
                raise self.fail(f"bad float {str(value)[:20]!r}")
            return float(value)
        if tag == "ref":
            if not isinstance(value, int) or value not in self.refs:
                raise self.fail(f"a reference to an unknown object {str(value)[:20]}")
            return self.refs[value]
        if tag == "array":
            name, n = self._pairs(value, 2, tag)
            if name not in self.arrays:
                raise self.fail(f"array {str(name)[:40]} is not in the file")
            arr = self.arrays[name]
            self._register(n, arr)
            return arr
        if tag == "scalar":
            dtype, v = self._pairs(value, 2, tag)
            try:
                dt = np.dtype(dtype)
                if dt.hasobject:
                    raise TypeError("object dtype")
                return dt.type(self.decode(v, depth + 1))
            except (TypeError, ValueError, OverflowError) as exc:
                raise self.fail(f"bad scalar {str(dtype)[:20]} ({exc})") from None
        if tag == "rng":
            kind, n, state = self._pairs(value, 3, tag)
            if kind not in BIT_GENERATORS:
                raise self.fail(f"bit generator {str(kind)[:30]!r} is not one of NumPy's")
            bit = getattr(np.random, kind)()
            state = self.decode(state, depth + 1)
            try:
                bit.state = state
            except (TypeError, ValueError, KeyError, OverflowError) as exc:
                raise self.fail(f"bad {kind} state ({exc})") from None
            rng = np.random.Generator(bit)
            self._register(n, rng)
            return rng
        if tag == "namedtuple":
            name, items = self._pairs(value, 2, tag)
            cls = self._class(name)
            if not (issubclass(cls, tuple) and hasattr(cls, "_fields") and isinstance(items, list)):
                raise self.fail(f"{name} is not a named tuple")
            if len(items) != len(cls._fields):
                raise self.fail(f"a {name} needs {len(cls._fields)} fields, got {len(items)}")
            return tuple.__new__(cls, [self.decode(v, depth + 1) for v in items])
        if tag == "enum":
            name, v = self._pairs(value, 2, tag)
            cls = self._class(name)
            if not issubclass(cls, enum.Enum):
                raise self.fail(f"{name} is not an enumeration")
            try:
                return cls(self.decode(v, depth + 1))
            except ValueError as exc:
                raise self.fail(str(exc)) from None
        if tag == "object":
            name, n, state = self._pairs(value, 3, tag)
            cls = self._class(name)
            if issubclass(cls, BaseException | enum.Enum):
                raise self.fail(f"{name} cannot be restored")
            obj = cls.__new__(cls)
            self._register(n, obj)
            state = self.decode(state, depth + 1)
            try:
                if getattr(type(obj), "__setstate__", None) is not None:
                    obj.__setstate__(state)
                else:
                    _set_plain_state(obj, state)
            except Exception as exc:  # a class's own __setstate__ met a state it cannot take
                raise self.fail(f"cannot restore a {name} ({type(exc).__name__}: {exc})") from None
            return obj
        raise self.fail(f"unknown state tag {str(tag)[:30]!r}")

    def _class(self, name: Any) -> type:
        if not isinstance(name, str) or ":" not in name:
            raise self.fail(f"bad class name {str(name)[:60]!r}")
        module, qualname = name.split(":", 1)
        if not (module == "dcee" or module.startswith("dcee.")):
            raise self.fail(f"class {name[:60]} is not dcee's (refused)")
        try:
            obj: Any = importlib.import_module(module)
            for part in qualname.split("."):
                obj = getattr(obj, part)
        except (ImportError, AttributeError):
            raise self.fail(f"class {name[:60]} does not exist in this dcee") from None
        if not isinstance(obj, type) or obj.__module__ != module:
            raise self.fail(f"{name[:60]} is not a class defined in {module}")
        return obj


def _set_plain_state(obj: Any, state: Any) -> None:
    """What ``object.__reduce_ex__`` restores: a dict, or (dict or None, slots dict)."""
    slots: dict = {}
    if isinstance(state, tuple) and len(state) == 2:
        state, slots = state
    if state is not None:
        if not isinstance(state, dict) or not all(isinstance(k, str) for k in state):
            raise TypeError("the state is not an attribute dictionary")
        obj.__dict__.update(state)
    for key, value in (slots or {}).items():
        object.__setattr__(obj, key, value)


def release(version: str) -> str:
    """The release a version string names: ``0.1.1`` of ``0.1.1.dev741+g1d53b98de`` (two
    installs of one release, a development checkout's venvs among them, read each other's
    files; the code version that wrote one is in its header)."""
    match = re.match(r"\d+(?:\.\d+)*", version)
    return match.group(0) if match else version


def read_state(path: Path, format_name: str) -> tuple[dict[str, Any], Any]:
    """(header, object) of the state file ``path`` written with ``format_name`` (module doc);
    one :class:`DceeInputError` for any file that is not one, or not intact."""
    path = Path(path)

    def fail(why: str) -> DceeInputError:
        return DceeInputError("checkpoint", f"{path}: {why}")

    if not path.exists():
        raise DceeInputError("checkpoint", f"no checkpoint at {path}")
    try:
        size = path.stat().st_size
        if size > MAX_ARRAY_BYTES + MAX_HEADER_BYTES:
            raise fail(f"{size} bytes, more than a state file may hold")
        data = path.read_bytes()
    except OSError as exc:
        raise fail(f"cannot be read ({exc.strerror or exc})") from None
    if len(data) < 64 + len(DIGEST) or data[-64 - len(DIGEST) : -64] != DIGEST:
        raise fail("not an intact dcee state file (no digest at its end: truncated, or not one)")
    if hashlib.sha256(data[:-64]).hexdigest().encode() != data[-64:]:
        raise fail("its digest does not match its bytes (corrupt or edited)")
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            try:
                info = zf.getinfo(HEADER)
            except KeyError:
                raise fail(f"not a dcee state file (no {HEADER})") from None
            if info.file_size > MAX_HEADER_BYTES:
                raise fail(f"its header declares {info.file_size} bytes (limit {MAX_HEADER_BYTES})")
            with zf.open(info) as fh:
                raw = fh.read(MAX_HEADER_BYTES + 1)
            try:
                header = json.loads(raw.decode("utf-8"))
            except (UnicodeDecodeError, ValueError, RecursionError) as exc:
                raise fail(f"its header is not JSON ({str(exc)[:80]})") from None
            if not isinstance(header, dict):
                raise fail("its header is not a JSON object")
            if header.get("format") != format_name:
                raise fail(f"format {str(header.get('format'))[:60]!r}, expected {format_name!r}")
            declared = header.get("arrays")
            if not isinstance(declared, dict):
                raise fail("its header lists no arrays")
            total = 0
            arrays = {}
            for name in declared:
                if not isinstance(name, str):
                    raise fail("an array name is not a string")
                arrays[name] = _read_array(zf, name, fail)
                total += arrays[name].nbytes
                if total > MAX_ARRAY_BYTES:
                    raise fail(f"its arrays exceed {MAX_ARRAY_BYTES} bytes")
    except DceeInputError:
        raise
    except zipfile.BadZipFile as exc:
        raise fail(f"not an intact dcee state file ({exc})") from None
    except (OSError, EOFError, ValueError, zipfile.LargeZipFile, NotImplementedError) as exc:
        # a zip whose records point outside it (a negative seek, an impossible size)
        raise fail(f"not an intact dcee state file ({type(exc).__name__}: {exc})") from None
    if header.get("checksum") != checksum(header, arrays):
        raise fail("its checksum does not match its content (corrupt or edited)")
    written = str(header.get("dcee_version"))
    if release(written) != release(package_version()):
        raise fail(
            f"written by dcee {written[:40]}, this is dcee {package_version()} (a state file "
            "is read by the release that wrote it)"
        )
    try:
        obj = _Decoder(arrays, fail).decode(header.get("state"))
    except RecursionError:
        raise fail(f"the state is nested deeper than {MAX_DEPTH}") from None
    return header, obj
