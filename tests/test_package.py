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
