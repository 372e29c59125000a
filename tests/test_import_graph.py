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


BENCHMARKS = ROOT.parent / "benchmarks"
#: The benchmark files that may read the library's private steps, with the reason
#: (``docs/benchmarks/studies.md``): every other script uses the public API.
PRIVATE_READERS = {
    "studies/candidates.py": "every candidate's held-out outcome per series (the choice's steps)",
}


def _private_imports(path: Path) -> list[str]:
    """The private ``sk_rtw`` modules or names a file imports (anywhere in it, by
    ``importlib.import_module``, and in code it runs from strings): any ``sk_rtw`` path
    with a component that starts with ``_``."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            names = [node.module] + [f"{node.module}.{alias.name}" for alias in node.names]
        elif (
            isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "import_module"
            and node.args and isinstance(node.args[0], ast.Constant)
        ):  # fmt: skip
            names = [str(node.args[0].value)]
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            pairs = _string_imports(node.value)
            names = [a for a, _ in pairs] + [f"{a}.{b}" for a, b in pairs]
        else:
            continue
        for name in names:
            parts = name.split(".")
            if parts[0] == "sk_rtw" and any(p.startswith("_") and p != "__version__"
                                            for p in parts[1:]):  # fmt: skip
                found.append(name)
    return found


def _string_imports(text: str) -> list[tuple[str, str]]:
    """``(module, name)`` of the ``from sk_rtw... import name`` and ``import sk_rtw...``
    lines in code held as a string."""
    pairs = []
    for line in text.splitlines():
        words = line.split()
        if len(words) >= 4 and words[0] == "from" and words[1].startswith("sk_rtw"):
            pairs += [(words[1], n.strip(",()")) for n in words[3:] if n.strip(",()")]
        elif len(words) >= 2 and words[0] == "import" and words[1].startswith("sk_rtw."):
            module, _, name = words[1].rstrip(",").rpartition(".")
            pairs.append((module, name))
    return pairs


def test_the_private_import_finder_finds_them(tmp_path):
    script = tmp_path / "script.py"
    script.write_text(
        "from sk_rtw import align\nfrom sk_rtw.align import _training\n"
        "import sk_rtw._heap\nCODE = '''\nfrom sk_rtw.estimators._selection import WINDOWS\n'''\n"
        "importlib.import_module('sk_rtw.align._training')\nDOC = 'see sk_rtw.dtw._search'\n"
    )
    found = _private_imports(script)
    assert "sk_rtw.align._training" in found and "sk_rtw._heap" in found
    assert "sk_rtw.estimators._selection" in found and "sk_rtw.align" not in found
    assert found.count("sk_rtw.align._training") == 2  # the import and import_module
    assert "sk_rtw.estimators._selection.WINDOWS" in found
    assert not any("dtw" in name for name in found)  # a mention is no import


def test_benchmarks_use_the_public_api_but_one_study():
    readers = sorted(
        str(path.relative_to(BENCHMARKS))
        for path in BENCHMARKS.rglob("*.py")
        if _private_imports(path)
    )
    assert readers == sorted(PRIVATE_READERS)
    assert all(name.startswith("studies/") for name in PRIVATE_READERS)


def _function_level_imports(path: Path) -> list[str]:
    """The package's own modules a file imports inside a function (relative imports, or
    ``sk_rtw...``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = []
    for function in ast.walk(tree):
        if not isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for node in ast.walk(function):
            own = isinstance(node, ast.ImportFrom) and (
                node.level or (node.module or "").startswith("sk_rtw")
            )  # fmt: skip
            own = own or (
                isinstance(node, ast.Import) and node.names[0].name.startswith("sk_rtw")
            )  # fmt: skip
            if own:
                found.append(f"{path.relative_to(ROOT.parent)}:{node.lineno}")
    return found


def test_no_function_level_import_of_the_package():
    """Every import of the package's own modules is at the top of its module, where the
    graph above sees it: a function-level import hides a circle or a primitive that
    sits too high."""
    hidden = [hit for path in MODULES.values() for hit in _function_level_imports(path)]
    assert hidden == []


MANIFOLD_WORDS = ("sphere", "spd", "quaternion", "euclidean")  # (a pose is their product)


def _names_in_code(path: Path) -> set[str]:
    """Every identifier a module's code uses or defines (names, attributes, imports,
    functions, arguments): its docstrings, comments and strings left out."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name):
            names.add(node.id)
        elif isinstance(node, ast.Attribute):
            names.add(node.attr)
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.arg):
            names.add(node.arg)
        elif isinstance(node, ast.alias):
            names.update(node.name.split("."))
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.update(node.module.split("."))
    return names


def test_the_dtw_package_names_no_manifold():
    """dtw/ runs recursions over point costs; every manifold's geometry, its compiled
    point distances and bounds included, is the manifolds' (their table,
    ``sk_rtw.manifolds._point_kernels``, is all dtw/ reads of it)."""
    named = {
        f"{module}: {name}"
        for module, path in MODULES.items() if module.startswith("sk_rtw.dtw")
        for name in _names_in_code(path)
        if any(word in name.lower() for word in MANIFOLD_WORDS)
    }  # fmt: skip
    assert named == set()
    reads = {
        target for module, targets in GRAPH.items() if module.startswith("sk_rtw.dtw")
        for target in targets if target.startswith("sk_rtw.manifolds")
    }  # fmt: skip
    assert reads <= {"sk_rtw.manifolds", "sk_rtw.manifolds._point_kernels"}


def test_the_name_finder_sees_code_not_prose(tmp_path):
    module = tmp_path / "m.py"
    module.write_text(
        '"""On a sphere."""\nfrom ._spd_kernels import f\nSEGMENT_SPHERE = 1\n'
        'def g(manifold="euclidean"):\n    return x.quaternion\n'
    )
    named = {n for n in _names_in_code(module) if any(w in n.lower() for w in MANIFOLD_WORDS)}
    assert named == {"_spd_kernels", "SEGMENT_SPHERE", "quaternion"}
