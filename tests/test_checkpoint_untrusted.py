"""Checkpoints are data, not code: a file that is not an intact checkpoint of this dcee version
and scenario is refused in one line, before anything in it runs or allocates (issue 80)."""

from __future__ import annotations

import hashlib
import io
import json
import pickle
import zipfile
from pathlib import Path

import numpy as np
import pytest

from dcee import state_file
from dcee.errors import DceeInputError
from dcee.runs import make_searcher, scenario_key, streams
from dcee.scenarios import load_scenario
from dcee.searcher import Searcher


def _scenario(**overrides):
    return load_scenario("paper:1").with_overrides(**{"search.particles": 300, **overrides})


@pytest.fixture(scope="module")
def saved(tmp_path_factory) -> Path:
    """A checkpoint of a real search (paper:1, 300 particles, two readings)."""
    sc = _scenario()
    _, filter_rng, planner_rng, _ = streams(0)
    from dcee.planning import get as get_planner

    searcher = make_searcher(sc, get_planner("infotaxis"), filter_rng, planner_rng)
    for k in range(2):
        searcher.tell(np.array([2.0 + k, 2.0, 4.0]), 0.0, time=float(k))
    return searcher.save(tmp_path_factory.mktemp("ckpt") / "search.ckpt")


def _members(path: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as zf:
        return {n: zf.read(n) for n in zf.namelist()}


def _zip(members: dict[str, bytes], out: Path) -> Path:
    """``members`` as a zip with the digest a forger can compute (state_file.DIGEST)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as zf:
        for name, data in members.items():
            zf.writestr(name, data)
        zf.comment = state_file.DIGEST + b"0" * 64
    data = bytearray(buf.getvalue())
    data[-64:] = hashlib.sha256(data[:-64]).hexdigest().encode()
    out.write_bytes(bytes(data))
    return out


def _rewrite(path: Path, out: Path, edit, checksum: bool = True) -> Path:
    """``path``'s checkpoint with ``edit(header)`` applied to its header (and its checksum
    recomputed, as a forger would)."""
    members = _members(path)
    header = json.loads(members["header.json"])
    edit(header)
    if checksum:
        arrays = {}
        for name in header.get("arrays", {}):
            arrays[name] = np.load(io.BytesIO(members[f"{name}.npy"]), allow_pickle=False)
        header["checksum"] = state_file.checksum(header, arrays)
    members["header.json"] = json.dumps(header).encode()
    return _zip(members, out)


def _refused(path: Path, match: str) -> None:
    with pytest.raises(DceeInputError, match=match) as info:
        Searcher.load(path)
    assert "\n" not in str(info.value)


def test_a_pickle_placed_as_a_checkpoint_runs_nothing(tmp_path) -> None:
    marker = tmp_path / "created-by-the-file"

    class Plant:
        def __reduce__(self):
            return (Path.touch, (marker,))

    ckpt = tmp_path / "search.ckpt"
    ckpt.write_bytes(pickle.dumps({"format": "dcee-searcher-checkpoint-1", "searcher": Plant()}))
    _refused(ckpt, "not an intact dcee state file")
    assert not marker.exists()


def test_a_flipped_byte_anywhere_is_refused(saved, tmp_path) -> None:
    data = saved.read_bytes()
    for at in (len(data) // 2, len(data) // 3, 200, len(data) - 300):
        bad = tmp_path / f"flip-{at}.ckpt"
        bad.write_bytes(data[:at] + bytes([data[at] ^ 0x10]) + data[at + 1 :])
        with pytest.raises(DceeInputError, match="checkpoint"):
            Searcher.load(bad)


def test_a_truncated_or_empty_file_is_refused(saved, tmp_path) -> None:
    data = saved.read_bytes()
    for size in (0, 10, len(data) // 2, len(data) - 1):
        bad = tmp_path / f"cut-{size}.ckpt"
        bad.write_bytes(data[:size])
        _refused(bad, "checkpoint")
    _refused(tmp_path / "absent.ckpt", "no checkpoint at")


def test_an_edit_without_thechecksum_is_refused(saved, tmp_path) -> None:
    def move(h):
        text = json.dumps(h["state"])
        assert '"time", 1.0]' in text
        h["state"] = json.loads(text.replace('"time", 1.0]', '"time", 5.0]'))

    bad = _rewrite(saved, tmp_path / "edited.ckpt", move, checksum=False)
    _refused(bad, "checksum does not match")


def test_another_version_format_or_scenario_is_refused(saved, tmp_path) -> None:
    old = _rewrite(saved, tmp_path / "v.ckpt", lambda h: h.update(dcee_version="0.0.1"))
    _refused(old, "written by dcee 0.0.1")
    fmt = _rewrite(saved, tmp_path / "f.ckpt", lambda h: h.update(format="other-1"))
    _refused(fmt, "format 'other-1'")
    assert Searcher.load(saved, scenario_key(_scenario())).filter is not None
    with pytest.raises(DceeInputError, match="a search of 'paper:1', not of 'paper:2'"):
        Searcher.load(saved, scenario_key(load_scenario("paper:2")))
    tweaked = _scenario(**{"sensor.threshold": 1e-3})
    with pytest.raises(DceeInputError, match="of 'paper:1' with other settings"):
        Searcher.load(saved, scenario_key(tweaked))


@pytest.mark.parametrize(
    "klass", ["builtins:eval", "os:system", "subprocess:Popen", "dcee.io:write_json", "dcee.x:Y"]
)
def test_only_dcee_classes_are_made(saved, tmp_path, klass: str) -> None:
    def plant(h):
        h["state"] = {"object": [klass, 0, {"dict": [["cmd", "touch x"]]}]}

    _refused(_rewrite(saved, tmp_path / "c.ckpt", plant), "class|not a class|is not dcee")


def test_declared_sizes_are_checked_before_memory_is_taken(saved, tmp_path) -> None:
    members = _members(saved)
    header = json.loads(members["header.json"])
    name = next(iter(header["arrays"]))
    # a .npy header that declares 10^12 float64 elements over a few bytes of data
    huge = b"\x93NUMPY\x01\x00" + b"v\x00"
    text = "{'descr': '<f8', 'fortran_order': False, 'shape': (1000000, 1000000), }"
    text = text.ljust(118) + "\n"
    members[f"{name}.npy"] = huge[:8] + len(text).to_bytes(2, "little") + text.encode() + b"1234"
    _refused(_zip(members, tmp_path / "huge.ckpt"), "declares")
    obj = io.BytesIO()
    np.save(obj, np.array([object()], dtype=object), allow_pickle=True)
    members[f"{name}.npy"] = obj.getvalue()
    _refused(_zip(members, tmp_path / "objects.ckpt"), "Python objects")


def test_deep_nesting_is_refused(saved, tmp_path) -> None:
    def deep(h):
        node: object = 1
        for _ in range(500):
            node = [node]
        h["state"] = node

    _refused(_rewrite(saved, tmp_path / "deep.ckpt", deep), "nested deeper than 200")
    members = _members(saved)
    members["header.json"] = b'{"format": "dcee-searcher-checkpoint-2", "s": ' + b"[" * 100_000
    _refused(_zip(members, tmp_path / "deeper.ckpt"), "header is not JSON")


def _resign(data: bytes) -> bytes:
    """``data`` with its trailing digest recomputed (a forger's file, or a flip before it)."""
    body = bytearray(data)
    if len(body) > 64:
        body[-64:] = hashlib.sha256(body[:-64]).hexdigest().encode()
    return bytes(body)


def fuzz_case(data: bytes, rng: np.random.Generator) -> bytes:
    """One corrupt variant of a checkpoint's bytes: 1-5 random bytes set, a random cut, and,
    every other case, the digest recomputed so that the zip, .npy and JSON readers see it."""
    case = bytearray(data)
    for at in rng.integers(0, len(case) - 64, size=int(rng.integers(1, 6))):
        case[at] = int(rng.integers(0, 256))
    if rng.random() < 0.3:
        case = case[: int(rng.integers(0, len(case)))]
    return _resign(bytes(case)) if rng.random() < 0.5 else bytes(case)


def test_random_corruption_never_escapes_as_another_error(saved, tmp_path) -> None:
    """A small fuzz (the benchmark `python studies/fuzz_readers.py` runs thousands): random
    byte changes and cuts give a searcher or one DceeInputError line, nothing else."""
    rng = np.random.default_rng(80)
    data = saved.read_bytes()
    bad = tmp_path / "fuzz.ckpt"
    for _ in range(100):
        bad.write_bytes(fuzz_case(data, rng))
        try:
            Searcher.load(bad)
        except DceeInputError as exc:
            assert "\n" not in str(exc)


def test_the_command_line_reads_a_checkpoint_as_a_node_would(saved, tmp_path, capsys) -> None:
    from tests.helpers import run_cli

    code, out, err = run_cli(["checkpoint", str(saved), "--json"], capsys)
    assert code == 0 and json.loads(out)["readings"] == 2 and err == ""
    code, out, _ = run_cli(
        ["checkpoint", str(saved), "--scenario", "paper:1", "--particles", "300"], capsys
    )
    assert code == 0 and "paper:1" in out
    data = saved.read_bytes()
    cases = {
        "truncated": data[: len(data) // 2],
        "flipped": data[:900] + bytes([data[900] ^ 4]) + data[901:],
        "pickle": pickle.dumps({"searcher": None}),
    }
    for name, content in cases.items():
        (tmp_path / name).write_bytes(content)
        code, out, err = run_cli(["checkpoint", str(tmp_path / name)], capsys)
        assert code == 2 and out == "" and err.count("\n") == 1, name
        assert err.startswith("dcee: error: checkpoint: ")
    code, _, err = run_cli(["checkpoint", str(saved), "--scenario", "paper:1"], capsys)
    assert code == 2 and "with other settings" in err and err.count("\n") == 1


def test_no_reader_in_the_package_unpickles() -> None:
    """No pickle anywhere in a path that reads a file (issue 80): the package neither imports
    pickle nor lets NumPy load pickled objects."""
    from pathlib import Path

    import dcee

    for path in Path(dcee.__file__).parent.rglob("*.py"):
        text = path.read_text(encoding="utf-8")
        for banned in ("import pickle", "pickle.load", "allow_pickle=True", "import dill"):
            assert banned not in text, f"{path.name}: {banned}"
