"""Sphinx configuration of the thermojitter documentation (built with -W: warnings are errors)."""

import thermojitter

project = "thermojitter"
author = "the thermojitter authors"
copyright = "2024-2026, the thermojitter authors"
release = thermojitter.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "numpydoc",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
exclude_patterns = ["_build"]

autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the signatures show them; the docstrings say the units
numpydoc_show_class_members = False
numpydoc_validation_checks: set[str] = set()

html_theme = "alabaster"
html_title = f"thermojitter {release}"
