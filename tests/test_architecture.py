"""The layering drawn in docs/design.md is what the code does.

Every import inside the package goes to the same or a lower layer, no two modules import each
other (directly or around a cycle), the interfaces (command line, ROS 2, Gymnasium) do not import
each other, and no module imports a private name (``_name``) from another package. Imports inside
functions count too (a lazy import is still a dependency); imports under ``if TYPE_CHECKING:``
are annotations only and do not count. The checks run on a copy of the package with a planted
violation, so they can fail.
"""

from __future__ import annotations

import ast
import shutil
from pathlib import Path

import pytest

import dcee

PACKAGE = Path(dcee.__file__).parent

LAYERS = {
    # base utilities: no dcee imports beyond each other ("dcee" is the top module alone)
    "dcee": 0,
    "dcee.errors": 0,
    "dcee.io": 0,
    "dcee.numeric": 0,
    "dcee.allocator": 0,
    "dcee.provenance": 0,
    "dcee.blas": 0,
    "dcee.kernel_cache": 0,  # where numba keeps compiled kernels (set before numba loads)
    "dcee.kernel_target": 0,  # the kernels' vector width (set before numba loads)
    "dcee.kernel_locator": 0,  # how numba files them there (numba imports it by name)
    "dcee.state_file": 0,  # state files that are data, not code (checkpoints)
    "dcee.limits": 0,  # what a reader of others' files will allocate
    "dcee.search_memory": 0,  # whether a search's particles fit the memory available
    "dcee.models": 1,
    "dcee.recordings": 1,  # plume recordings on disk: CF reader, header layout, statistics
    "dcee.geo": 1,  # geographic coordinates: the local frame, site files, answers on a map
    "dcee.estimation": 2,
    "dcee.stopping": 2,  # when the posterior is narrow enough to end a search
    "dcee.planning": 3,
    "dcee.planners": 3,  # the public alias of dcee.planning
    "dcee.scenarios": 3,  # configuration: builds models and priors, knows no planner
    "dcee.exploration": 4,  # where readings become informative when no move within reach is
    "dcee.searcher": 4,
    "dcee.simulation": 5,  # the truths
    "dcee.runs": 6,  # one search: assemble, step, record, score, save
    "dcee.campaign": 7,  # many searches: executors and resumption
    "dcee.robot": 7,  # the ROS-free robot loop, bags, replay
    "dcee.analysis": 8,
    "dcee.console": 9,  # what every interface prints
    "dcee.perf": 9,
    "dcee.cli": 10,
    "dcee.ros": 10,
    "dcee.gym": 10,
}
INTERFACES = ("dcee.cli", "dcee.ros", "dcee.gym")
"""Top-layer packages that must not import each other (they share the console layer instead)."""


def module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def owner(module: str) -> str | None:
    """The LAYERS entry a module belongs to: the longest package prefix, or the top module
    ``dcee`` only for itself (so a new module without an entry is caught)."""
    keys = [k for k in LAYERS if module == k or (k != "dcee" and module.startswith(k + "."))]
    return max(keys, key=len) if keys else None


def layer_of(module: str) -> int:
    key = owner(module)
    if key is None:
        raise KeyError(f"{module} has no layer in LAYERS (tests/test_architecture.py)")
    return LAYERS[key]


MAX_LINES = 450
"""The longest a module may be, in lines (docs/design.md)."""


def _imports(tree: ast.AST, annotations: bool = False) -> list[tuple[str, list[str]]]:
    """(dcee module, names imported from it) anywhere in the file; under
    ``if TYPE_CHECKING:`` only with ``annotations``."""
    found: list[tuple[str, list[str]]] = []

    def visit(node: ast.AST) -> None:
        typing_only = isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)
        if typing_only and not annotations:
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module.split(".")[0] == "dcee":
                found.append((node.module, [a.name for a in node.names]))
        elif isinstance(node, ast.Import):
            found.extend((a.name, []) for a in node.names if a.name.split(".")[0] == "dcee")
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return found


def import_graph(root: Path = PACKAGE, annotations: bool = False) -> dict[str, set[str]]:
    modules = {module_name(p, root): p for p in root.rglob("*.py")}
    graph = {}
    for name, path in modules.items():
        targets = set()
        for module, names in _imports(ast.parse(path.read_text()), annotations):
            targets.add(module)
            targets.update(f"{module}.{n}" for n in names)  # "from dcee import planners"
        graph[name] = {t for t in targets if t in modules and t != name}
    return graph


def upward_imports(graph: dict[str, set[str]]) -> list[str]:
    return sorted(
        f"{src} (layer {layer_of(src)}) imports {dst} (layer {layer_of(dst)})"
        for src, targets in graph.items()
        for dst in targets
        if layer_of(dst) > layer_of(src)
    )


def interface_imports(graph: dict[str, set[str]]) -> list[str]:
    def interface(module: str) -> str | None:
        return next((i for i in INTERFACES if module == i or module.startswith(i + ".")), None)

    return sorted(
        f"{src} imports {dst}"
        for src, targets in graph.items()
        for dst in targets
        if interface(src) and interface(dst) and interface(src) != interface(dst)
    )


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    # a package's __init__ re-exporting its own submodules is not a cycle between layers
    edges = {
        src: {d for d in targets if not (d.startswith(src + ".") and src != "dcee")}
        for src, targets in graph.items()
    }
    state: dict[str, int] = {}
    found: list[list[str]] = []

    def dfs(node: str, path: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == 1:
                found.append([*path[path.index(nxt) :], nxt] if nxt in path else [node, nxt])
            elif nxt not in state:
                dfs(nxt, [*path, nxt])
        state[node] = 2

    for node in sorted(edges):
        if node not in state:
            dfs(node, [node])
    return found


def private_imports(root: Path = PACKAGE) -> list[str]:
    """``from dcee.a.b import _name`` where the importer is outside package ``dcee.a``."""
    out = []
    for path in root.rglob("*.py"):
        src = module_name(path, root)
        for module, names in _imports(ast.parse(path.read_text())):
            home = ".".join(module.split(".")[:2])
            same_package = src == home or src.startswith(home + ".")
            for n in names:
                if n.startswith("_") and not n.startswith("__") and not same_package:
                    out.append(f"{src} imports {module}.{n}")
    return sorted(out)


def long_modules(root: Path = PACKAGE) -> list[str]:
    return sorted(
        f"{module_name(path, root)}: {n} lines"
        for path in root.rglob("*.py")
        if (n := len(path.read_text().splitlines())) > MAX_LINES
    )


def test_every_module_has_a_layer():
    missing = [m for m in import_graph() if owner(m) is None]
    assert not missing, missing


def test_no_module_imports_a_higher_layer():
    upward = upward_imports(import_graph())
    assert not upward, "\n".join(upward)


def test_no_import_cycles():
    found = cycles(import_graph(annotations=True))
    assert not found, "\n".join(" -> ".join(c) for c in found)


def test_no_module_is_longer_than_the_limit():
    found = long_modules()
    assert not found, f"split by job (at most {MAX_LINES} lines): " + ", ".join(found)


def test_interfaces_do_not_import_each_other():
    found = interface_imports(import_graph())
    assert not found, "\n".join(found)


def test_no_module_imports_a_private_name_from_another_package():
    found = private_imports()
    assert not found, "\n".join(found)


@pytest.fixture
def planted(tmp_path: Path) -> Path:
    """A copy of the package to plant violations in."""
    root = tmp_path / "dcee"
    shutil.copytree(PACKAGE, root, ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    return root


def _plant(root: Path, module: str, line: str) -> None:
    path = root / (module.replace(".", "/") + ".py")
    path.write_text(path.read_text() + f"\n\ndef _planted():\n    {line}\n")


def test_the_checks_catch_a_planted_upward_import(planted: Path):
    _plant(planted, "models.plume", "from dcee.cli import main  # noqa")
    assert upward_imports(import_graph(planted)) == [
        "dcee.models.plume (layer 1) imports dcee.cli (layer 10)"
    ]


def test_the_checks_catch_a_planted_cycle_and_interface_import(planted: Path):
    _plant(planted, "ros.node", "import dcee.cli  # noqa")
    _plant(planted, "runs.streams", "from dcee.runs.episode import run_episode  # noqa")
    graph = import_graph(planted)
    assert interface_imports(graph) == ["dcee.ros.node imports dcee.cli"]
    assert any("dcee.runs.streams" in c and "dcee.runs.episode" in c for c in cycles(graph))


def test_the_checks_catch_a_planted_private_import_and_an_unlayered_module(planted: Path):
    _plant(planted, "gym.env", "from dcee.runs.episode import _private  # noqa")
    (planted / "newpackage.py").write_text("")
    assert private_imports(planted) == ["dcee.gym.env imports dcee.runs.episode._private"]
    assert owner(module_name(planted / "newpackage.py", planted)) is None


def test_the_checks_catch_a_planted_long_module_and_annotation_cycle(planted: Path):
    (planted / "models" / "long.py").write_text("x = 1\n" * (MAX_LINES + 1))
    assert f"dcee.models.long: {MAX_LINES + 1} lines" in long_modules(planted)
    # sensor imports plume; plume naming sensor in an annotation closes a circle
    path = planted / "models" / "plume.py"
    path.write_text(
        path.read_text() + "\nif TYPE_CHECKING:\n    from dcee.models.sensor import Sensor\n"
    )
    assert not any("dcee.models.plume" in c for c in cycles(import_graph(planted)))
    assert any(
        "dcee.models.plume" in c and "dcee.models.sensor" in c
        for c in cycles(import_graph(planted, annotations=True))
    )
