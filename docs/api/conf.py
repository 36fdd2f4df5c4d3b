"""Sphinx configuration of abdsim's API reference (built from the docstrings).

Build: ``sphinx-build -W -b html docs/api abdsim_out/api`` (``-W``: a warning is an error,
as in the test that builds it).
"""

project = "abdsim"
author = "abdsim contributors"
extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon"]
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": False}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
napoleon_google_docstring = True
napoleon_numpy_docstring = False
html_theme = "alabaster"
exclude_patterns = ["_build"]
# "Attributes:" sections become fields of their class, not second descriptions of the
# dataclass fields autodoc already lists.
napoleon_use_ivar = True


def _escape_bars(app, what, name, obj, options, lines):
    """Docstrings write norms as |Δp|, which reStructuredText reads as substitutions."""
    lines[:] = [line.replace("|", "\\|") for line in lines]


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars)
