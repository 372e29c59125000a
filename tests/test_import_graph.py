"""The package's import graph, drawn from the code: no circle of modules (imports inside
functions included, ``if TYPE_CHECKING:`` blocks excluded), and no module outside
``sk_rtw.dtw`` that reaches into its private modules."""

from __future__ import annotations

import ast
from pathlib import Path

import sk_rtw

ROOT = Path(sk_rtw.__file__).parent


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(p): p for p in ROOT.rglob("*.py")}


def _targets(module: str, path: Path) -> set[str]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    typing_only = {
        id(node)
        for block in ast.walk(tree)
        if isinstance(block, ast.If) and "TYPE_CHECKING" in ast.unparse(block.test)
        for node in ast.walk(block)
    }
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    out = set()
    for node in ast.walk(tree):
        if id(node) in typing_only:
            continue
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            stem = ".".join(base + ([node.module] if node.module else []))
            names = [f"{stem}.{a.name}" if f"{stem}.{a.name}" in MODULES else stem
                     for a in node.names]  # fmt: skip
        else:
            continue
        out.update(n for n in names if n in MODULES and n != module)
    return out


GRAPH = {module: _targets(module, path) for module, path in MODULES.items()}


def _circles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    circles = []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    circles.append(sorted(component))
    return circles


def test_the_circle_finder_finds_a_circle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert _circles(graph) == [["a", "b", "c"]]
    assert _circles({"a": {"b"}, "b": set()}) == []


def test_the_graph_sees_imports_inside_functions():
    assert "sk_rtw.dtw._kernels" in GRAPH["sk_rtw.dtw._costs"]
    assert len(GRAPH) > 50


def test_no_module_imports_itself_back():
    assert _circles(GRAPH) == []


def test_only_the_dtw_package_opens_its_private_modules():
    reaching_in = sorted(
        (module, target)
        for module, targets in GRAPH.items()
        for target in targets
        if target.startswith("sk_rtw.dtw._") and not module.startswith("sk_rtw.dtw")
    )
    assert reaching_in == []


def _package(module: str) -> str:
    """The subpackage (or top-level module) of ``sk_rtw`` a module belongs to."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def test_packages_stand_on_floors():
    """No circle of subpackages: a lower one (manifolds, utils, the settings, dtw, align)
    never imports a higher one (methods, estimators)."""
    packages: dict[str, set[str]] = {}
    for module, targets in GRAPH.items():
        if module == "sk_rtw":  # the top-level door imports everything
            continue
        packages.setdefault(_package(module), set()).update(
            _package(t) for t in targets if _package(t) not in (_package(module), "sk_rtw")
        )
    for package in list(packages.values()):
        for target in package:
            packages.setdefault(target, set())
    assert _circles(packages) == []
    assert "align" not in packages["dtw"] and "methods" not in packages["align"]
    assert "estimators" not in packages["methods"] and "align" not in packages["_settings"]
