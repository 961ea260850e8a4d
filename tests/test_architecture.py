"""The layering drawn in docs/design.md is what the code does: every import inside the package
goes to the same or a lower layer, and no two modules import each other (directly or around a
cycle), counting imports inside functions too (a lazy import is still a dependency). Imports
under ``if TYPE_CHECKING:`` are annotations only and do not count."""

import ast
from pathlib import Path

import dcee

PACKAGE = Path(dcee.__file__).parent

LAYERS = {
    # base utilities: no dcee imports beyond each other
    "dcee": 0,
    "dcee.errors": 0,
    "dcee.io": 0,
    "dcee.numeric": 0,
    "dcee.allocator": 0,
    "dcee.provenance": 0,
    "dcee.models": 1,
    "dcee.estimation": 2,
    "dcee.planning": 3,
    "dcee.planners": 3,  # the public alias of dcee.planning
    "dcee.scenarios": 3,  # configuration: builds models and priors, knows no planner
    "dcee.searcher": 4,
    "dcee.simulation": 5,
    "dcee.campaign": 6,
    "dcee.analysis": 7,
    "dcee.cli": 8,
    "dcee.perf": 8,
    "dcee.gym": 8,  # the Gymnasium interface
    "dcee.ros": 8,  # the robot interface (ROS 2 node, demo, bags, replay)
}


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def layer_of(module: str) -> int:
    best = max((k for k in LAYERS if module == k or module.startswith(k + ".")), key=len)
    return LAYERS[best]


def _runtime_imports(tree: ast.AST) -> set[str]:
    """dcee modules imported anywhere in the file except under ``if TYPE_CHECKING:``."""
    found: set[str] = set()

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module.split(".")[0] == "dcee":
                found.add(node.module)
                for alias in node.names:  # "from dcee import planners" names a module
                    found.add(f"{node.module}.{alias.name}")
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.split(".")[0] == "dcee")
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return found


def import_graph() -> dict[str, set[str]]:
    modules = {module_name(p): p for p in PACKAGE.rglob("*.py")}
    graph = {}
    for name, path in modules.items():
        targets = _runtime_imports(ast.parse(path.read_text()))
        graph[name] = {t for t in targets if t in modules and t != name}
    return graph


def test_no_module_imports_a_higher_layer():
    upward = [
        f"{src} (layer {layer_of(src)}) imports {dst} (layer {layer_of(dst)})"
        for src, targets in import_graph().items()
        for dst in targets
        if layer_of(dst) > layer_of(src)
    ]
    assert not upward, "\n".join(sorted(upward))


def test_no_import_cycles():
    graph = import_graph()
    # a package's __init__ re-exporting its own submodules is not a cycle between layers
    edges = {
        src: {d for d in targets if not (d.startswith(src + ".") and src != "dcee")}
        for src, targets in graph.items()
    }
    state: dict[str, int] = {}
    cycles: list[list[str]] = []

    def dfs(node: str, path: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == 1:
                cycles.append([*path[path.index(nxt) :], nxt] if nxt in path else [node, nxt])
            elif nxt not in state:
                dfs(nxt, [*path, nxt])
        state[node] = 2

    for node in sorted(edges):
        if node not in state:
            dfs(node, [node])
    assert not cycles, "\n".join(" -> ".join(c) for c in cycles)


def test_every_module_has_a_layer():
    for name in import_graph():
        assert layer_of(name) is not None
