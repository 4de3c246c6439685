"""The package's layout: its imports, read with ``ast``, point one way.

Every ``import`` and ``from ... import`` of every module counts, at module level and inside
functions alike (a function's import runs when it is called, and a circle through it is
a circle); only the imports under ``if TYPE_CHECKING:`` do not, since they never run.
"""

import ast
from collections import defaultdict
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "kcplan"


def _modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _owner(name: str) -> str | None:
    """The module of kcplan's that ``import name`` runs last (a name inside a module is
    that module's)."""
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def _imports(module: str) -> tuple[set[str], set[str]]:
    """kcplan's modules and the other top-level packages ``module`` imports."""
    path = MODULES[module]
    tree = ast.parse(path.read_text(), filename=str(path))
    typing_only = {
        id(node)
        for branch in ast.walk(tree)
        if isinstance(branch, ast.If) and "TYPE_CHECKING" in ast.unparse(branch.test)
        for statement in branch.body
        for node in ast.walk(statement)
    }
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    ours, theirs = set(), set()
    for node in ast.walk(tree):
        if id(node) in typing_only:
            continue
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package
                for _ in range(node.level - 1):
                    parent = parent.rpartition(".")[0]
                base = f"{parent}.{base}" if base else parent
            names = [f"{base}.{alias.name}" for alias in node.names] if base else []
            if base and not base.startswith("kcplan"):
                names = [base]
        else:
            continue
        for name in names:
            if name.split(".")[0] == "kcplan":
                target = _owner(name)
                if target is not None and target != module:
                    ours.add(target)
            else:
                theirs.add(name.split(".")[0])
    return ours, theirs


GRAPH = {module: _imports(module) for module in MODULES}


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def _folder(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "kcplan"


def _folders() -> dict[str, set[str]]:
    out: dict[str, set[str]] = defaultdict(set)
    for module, (ours, _) in GRAPH.items():
        out[_folder(module)]
        for target in ours:
            if _folder(target) != _folder(module):
                out[_folder(module)].add(_folder(target))
    return out


def test_the_walk_sees_the_imports():
    """The walk itself: a module-level, a function-level and a relative import found."""
    assert "kcplan.planning.native" in GRAPH["kcplan.planning.problem"][0]
    assert "kcplan.arm.kinematics" in GRAPH["kcplan.arm.model"][0]
    assert "ompl" in GRAPH["kcplan.planning.problem"][1]
    assert "kcplan._kernel" in GRAPH["kcplan.geometry.enclosing"][0]  # inside a function
    assert _circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_no_module_imports_itself_back():
    assert _circles({m: ours for m, (ours, _) in GRAPH.items()}) == []


def test_no_folder_imports_itself_back():
    """Folders too: a module of one folder reaching into another that reaches back is a
    circle of the architecture even when the modules themselves form none."""
    assert _circles(_folders()) == []


ORDER = {  # a folder and the folders of kcplan's it may import
    "_kernel": set(),
    "geometry": {"_kernel"},
    "kc": {"geometry"},
    # what is done to a path: the curve's mathematics, and its blends certified
    "trajectory": {"_kernel", "arm", "certification", "geometry"},
    # where an edge is decided; where a path is made
    "certification": {"_kernel", "arm", "files", "geometry", "kc", "world"},
    "planning": {"_kernel", "arm", "certification", "geometry", "scenarios", "trajectory", "world"},
    "cover": {"geometry", "files"},
    "world": {"_kernel", "cover", "files", "geometry"},
}


@pytest.mark.parametrize("folder", sorted(ORDER))
def test_dependencies_point_down(folder):
    """The compiled kernel imports nothing of kcplan's, the mathematics nothing but the
    mathematics below it, the world nothing of the planners; nothing below the command
    line imports it."""
    assert _folders()[folder] <= ORDER[folder]
    assert not [f for f, targets in _folders().items() if "cli" in targets and f != "cli"]


@pytest.mark.parametrize("folder", ["geometry", "kc", "cover", "trajectory", "certification"])
def test_the_mathematics_never_imports_ompl_or_fcl(folder):
    """Nor does the certification: OMPL calls it, never the other way (python-fcl is the
    arm's Python twin's narrow phase, reached through kcplan.arm.world)."""
    for module, (_, theirs) in GRAPH.items():
        if _folder(module) == folder:
            assert not theirs & {"ompl", "fcl", "coal"}, module
