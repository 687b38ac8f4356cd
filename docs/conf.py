"""Sphinx configuration: ``make docs`` builds the HTML with warnings as errors."""

import os

import rough

project = "rough"
author = "the rough developers"
copyright = "2026, the rough developers"
release = version = rough.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "sphinx_click",
    "sphinx_gallery.gen_gallery",
    "sphinxcontrib.programoutput",
    "myst_parser",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "examples/README.rst", "auto_examples/*.ipynb", "auto_examples/*.py"]
html_theme = "furo"
html_title = f"rough {release}"
default_role = "code"
nitpicky = False
# Text is shown as written: smartquotes would turn the "--" of option names into en
# dashes and the quotes of shell examples into curly ones, so pasted examples fail.
smartquotes = False

autodoc_default_options = {"members": False}
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("SOURCE_DATE_EPOCH", "1767225600")
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "matplotlib_animations": False,
}
