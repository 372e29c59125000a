"""Sphinx configuration of the sk_rtw documentation."""

from __future__ import annotations

import os
import re
import warnings

import sk_rtw

project = "sk_rtw"
author = "sk_rtw developers"
copyright = "2026, sk_rtw developers"
release = sk_rtw.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "matplotlib.sphinxext.plot_directive",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "examples/README.rst", "**/*.ipynb", "auto_examples/*.md5"]
templates_path = ["_templates"]

myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3

autosummary_generate = True
autodoc_default_options = {"members": True, "inherited-members": False}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

intersphinx_mapping = {
    "python": ("https://docs.python.org/3", None),
    "numpy": ("https://numpy.org/doc/stable/", None),
    "sklearn": ("https://scikit-learn.org/stable/", None),
}
# No network during the build: intersphinx inventories are not fetched; references to
# them stay plain text.
intersphinx_disabled_reftypes = ["*"]
intersphinx_timeout = 1
if os.environ.get("SK_RTW_DOCS_OFFLINE", "1") == "1":
    intersphinx_mapping = {}

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "remove_config_comments": True,
    "show_memory": False,
    "min_reported_time": 1,
}

plot_include_source = False
plot_html_show_source_link = False
plot_html_show_formats = False
plot_formats = [("png", 100)]

html_theme = "pydata_sphinx_theme"
html_title = "sk_rtw"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_static_path: list[str] = []

warnings.filterwarnings("ignore", message="Matplotlib is currently using agg")

_STAR = re.compile(r"(?<=[\s(,\[])\*(?=[A-Za-z_])")


def _escape_star_args(app, what, name, obj, options, lines):
    """Escape ``*point_shape`` in shape descriptions outside inline literals.

    Docstrings write shapes as ``(n, T, *point_shape)``; in plain text reST would read the
    star as the start of an emphasis.
    """
    for i, line in enumerate(lines):
        parts = line.split("``")
        parts[::2] = [_STAR.sub(r"\\*", part) for part in parts[::2]]
        lines[i] = "``".join(parts)


def setup(app):
    app.connect("autodoc-process-docstring", _escape_star_args, priority=100)
