"""Packaging facts users rely on."""

import importlib.metadata
import subprocess
import sys
from pathlib import Path

import sk_rtw


def test_version_has_one_source():
    assert importlib.metadata.version("sk-rtw") == sk_rtw.__version__


def test_package_is_typed():
    assert (Path(sk_rtw.__file__).parent / "py.typed").is_file()


def test_importing_the_package_does_not_import_aeon():
    # aeon is an optional dependency (benchmarks, tests, gallery): never import it
    code = "import sys, sk_rtw, sk_rtw.utils, sk_rtw.datasets; print('aeon' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_importing_the_package_does_not_import_the_movement_models():
    # movement-primitives, gmr, pytransform3d: the lfd extra, for benchmarks and the gallery
    code = (
        "import sys, sk_rtw, sk_rtw.statistics; "
        "print(any(m in sys.modules for m in ('movement_primitives', 'gmr', 'pytransform3d')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_the_estimator_modules_import_one_way():
    """Class means and k-means share estimators/_core.py; neither imports the other."""
    import ast

    folder = Path(sk_rtw.__file__).parent / "estimators"

    def imported(name):
        tree = ast.parse((folder / f"{name}.py").read_text())
        return {
            node.module
            for node in ast.walk(tree)
            if isinstance(node, ast.ImportFrom) and node.module
        }

    assert "_kmeans" not in imported("_averager") and "_averager" not in imported("_kmeans")
    assert "_core" in imported("_averager") and "_core" in imported("_kmeans")
    assert not {"_averager", "_kmeans", "_classifier"} & imported("_core")
