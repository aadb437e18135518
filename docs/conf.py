"""Sphinx configuration of satmd's documentation site (`make docs`; `make docs-check` in CI).

Nothing is fetched from the network at build time: the intersphinx inventories of numpy, scipy,
torch, matplotlib, scikit-learn and Python are written from the installed packages
(``_ext/offline_inventory.py``), the API pages from the package's ``__all__`` lists
(``_ext/api_pages.py``), and the results page's tables from ``benchmarks/results/*.json``
(``benchmarks/readme_tables.py``, which `tests/test_readme.py` checks). The gallery runs
``examples/plot_*.py``; ``-D plot_gallery=0`` builds it without running them.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE / "_ext"))

import api_pages  # noqa: E402
import offline_inventory  # noqa: E402

import satmd  # noqa: E402

project = "satmd"
author = "the satmd developers"
copyright = "satmd developers, MIT licence"
version = release = satmd.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.intersphinx",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "myst_parser",
    "docstring_notation",  # _ext/: |A1|, (*batch, n) and lists under a line, as satmd writes them
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = ["_build", "_ext", "_templates", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.json", "auto_examples/*.md5",
                    "auto_examples/*.codeobj.json"]
default_role = "py:obj"  # `name` in a docstring is a cross-reference, as in numpy's and scipy's docs
nitpicky = False         # a name the inventories do not hold stays code text, not an error
suppress_warnings = ["config.cache"]  # sphinx-gallery's config holds functions: Sphinx cannot pickle them

# --- API reference ----------------------------------------------------------------------------------
api_pages.write(HERE / "api")
autosummary_generate = True
autosummary_imported_members = True
autodoc_typehints = "signature"
autodoc_preserve_defaults = True  # `freq_hz=PAPER_GRID_HZ`, not the 60 numbers
autodoc_member_order = "bysource"
autodoc_default_options = {"show-inheritance": True}
numpydoc_show_class_members = False   # members come from the class template (autodoc), not numpydoc tables
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False      # satmd's docstrings often describe a parameter on its type line
numpydoc_validation_checks: set = set()  # tests/test_docstrings.py checks parameters against signatures

# --- cross-links, offline ---------------------------------------------------------------------------
intersphinx_mapping = offline_inventory.intersphinx_mapping(Path(os.environ.get(
    "SATMD_DOCS_CACHE", ROOT / "build" / "intersphinx")))
intersphinx_timeout = 1

# --- Markdown pages ---------------------------------------------------------------------------------
myst_enable_extensions = ["colon_fence", "deflist"]
myst_heading_anchors = 3

# --- gallery ------------------------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "ignore_pattern": r"^(?!plot_)",  # examples/*.py without the prefix are command-line scripts
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "abort_on_example_error": True,
    "remove_config_comments": True,
    "min_reported_time": 0,
    "show_memory": False,
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
    "matplotlib_animations": False,
    "reference_url": {"satmd": None},
    "backreferences_dir": None,
    "show_signature": False,
}

# --- HTML -------------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"satmd {release}"
html_static_path = ["_static"]
html_theme_options = {
    "navbar_align": "left",
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False
html_copy_source = False
