"""The state file's layout: its limits, names and checksum (:mod:`dcee.state_file`)."""

from __future__ import annotations

import hashlib
import json
from typing import Any

import numpy as np

MAX_HEADER_BYTES = 64 * 2**20
"""Largest ``header.json`` read (64 MiB; a 20,000-particle checkpoint's is a few kB)."""

MAX_ARRAY_BYTES = 2**30
"""Largest total of the arrays' declared sizes read (1 GiB; the largest checkpoint measured, a
20,000-particle search at the paper's scale, holds a few MB: docs/robot.md)."""

MAX_DEPTH = 200
"""Deepest nesting of the object graph written or read."""

BIT_GENERATORS = ("PCG64", "PCG64DXSM", "Philox", "SFC64", "MT19937")
"""The NumPy bit generators a state file may name."""

HEADER = "header.json"
DIGEST = b"sha256:"
"""The zip archive's comment: this, then the SHA-256 (hex) of every byte of the file before
those 64 hex digits (so a flipped byte anywhere, the zip's own records included, is seen)."""


def checksum(header: dict[str, Any], arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 (hex) over the header without its ``checksum`` (canonical JSON) and every
    array's name, dtype, shape and bytes, in name order."""
    digest = hashlib.sha256()
    body = {k: v for k, v in header.items() if k != "checksum"}
    digest.update(json.dumps(body, sort_keys=True, allow_nan=False).encode())
    for name in sorted(arrays):
        a = np.ascontiguousarray(arrays[name])
        digest.update(f"{name}|{a.dtype.str}|{a.shape}|".encode())
        digest.update(a.reshape(-1).view(np.uint8).data if a.size else b"")
    return digest.hexdigest()
