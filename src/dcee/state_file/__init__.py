"""State files that are data, not code: an object graph of dcee's own classes, NumPy arrays and
random generators saved as a zip of ``.npy`` arrays and one JSON header, read without pickle.

A search checkpoint (:meth:`dcee.searcher.Searcher.save`) is written by this module. Reading a
pickle runs whatever code its author put in it; reading a state file runs none:

* **Layout** (a zip archive, members stored uncompressed, its comment ``sha256:`` and the digest
  of every byte before the digest): ``header.json`` (UTF-8 JSON, at most
  :data:`MAX_HEADER_BYTES`) and one ``<name>.npy`` per array (NumPy's own format, read with
  ``allow_pickle=False``: an object array is refused). The header holds ``format`` (the
  caller's layout name and version), ``dcee_version``, ``code`` (the code version that wrote
  it), the caller's ``meta`` (a checkpoint: the scenario's name and identity), ``arrays``
  (each array's dtype and shape), ``state`` (the object graph, below) and ``checksum`` (SHA-256
  over the header without it and every array's name, dtype, shape and bytes).
* **The object graph** in ``state`` is JSON in which every object is one of: null, true/false,
  a number, a string, a list, or a single-key object tagging what it stands for —
  ``{"dict": [[key, value], ...]}``, ``{"tuple": [...]}``, ``{"set": [...]}``, ``{"float":
  "nan"}`` (and ``"inf"``, ``"-inf"``), ``{"array": [name, id]}``, ``{"scalar": [dtype,
  value]}``, ``{"rng": [bit generator, id, state]}``, ``{"object": [class, id, state]}`` (an
  instance of a class of dcee itself, ``"dcee.module:Class"``, its ``__getstate__``), ``{"ref":
  id}`` (an object, array or generator met before: shared objects stay shared), ``{"enum":
  [class, value]}``, ``{"namedtuple": [class, [fields]]}``.
* **What reading may do**: import a module of dcee itself and make an instance of a class
  defined there (``cls.__new__``, then its ``__setstate__`` or its ``__dict__``), a NumPy array
  of a plain dtype, a bit generator NumPy ships (:data:`BIT_GENERATORS`). Nothing else: no
  callable named in the file is called, no module outside dcee is imported.
* **Limits checked before memory is taken**: the header's size, each array's declared size
  (from its ``.npy`` header, against the zip entry's size) and their total
  (:data:`MAX_ARRAY_BYTES`), the graph's nesting (:data:`MAX_DEPTH`).

Every failure to read is one :class:`dcee.errors.DceeInputError` naming the file and what is
wrong (missing, not a zip, truncated, a member's CRC, the checksum, the format, the release).
"""

from __future__ import annotations

from dcee.state_file.layout import (
    BIT_GENERATORS,
    DIGEST,
    MAX_ARRAY_BYTES,
    MAX_DEPTH,
    MAX_HEADER_BYTES,
    checksum,
)
from dcee.state_file.read import read_state
from dcee.state_file.write import write_state

__all__ = [
    "BIT_GENERATORS",
    "DIGEST",
    "MAX_ARRAY_BYTES",
    "MAX_DEPTH",
    "MAX_HEADER_BYTES",
    "checksum",
    "read_state",
    "write_state",
]
