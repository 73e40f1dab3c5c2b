"""Sphinx configuration of the shipgym documentation site.

Build it from the repository root (the ``docs`` extra brings the tools)::

    pip install -e ".[docs]"
    python -m sphinx -W -b html docs docs/_build/html

* the API reference (``reference/api.rst``) is autosummary over the numpydoc docstrings; the
  stubs go to ``reference/generated/`` (written at every build, not kept in the repository);
* the command-line reference (``reference/cli.rst``) is generated from the argument parser,
  ``shipgym.cli.build_parser``, by sphinx-argparse;
* the gallery runs every ``examples/gallery/plot_*.py`` at build time and shows its figures
  (output in ``auto_examples/``, also written at every build);
* the user guide and the results pages are Markdown (myst-parser). The figures and JSON files
  beside them are written by the scripts in ``scripts/``: pages include them by relative path,
  and they are not pages themselves.

No extension reaches the network: intersphinx is off.
"""

from __future__ import annotations

import importlib.util
import inspect
import os
import re
import sys
from pathlib import Path
from typing import Any

# the examples draw with matplotlib in a process without a display
os.environ.setdefault("MPLBACKEND", "Agg")

ROOT = Path(__file__).resolve().parents[1]
# ``controllers`` and ``shipgym`` from this checkout, installed or not
sys.path.insert(0, str(ROOT))

import shipgym  # noqa: E402

# -- Project ----------------------------------------------------------------------------------
project = "shipgym"
author = "the shipgym authors"
copyright = "the shipgym authors, MIT licence"
release = shipgym.__version__
version = release

# -- Extensions -------------------------------------------------------------------------------
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
    "sphinxarg.ext",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = [
    "_build",
    # the Markdown tables the scripts write next to their figures are included by the results
    # pages, they are not pages of their own; nor are the data files
    "*.md",
    "**/*.json",
    "**/*.csv",
    "benchmark",
    "user_log",
    # sphinx-gallery's by-products beside the pages it writes
    "auto_examples/*.ipynb",
    "auto_examples/*.py",
    "auto_examples/*.zip",
    "auto_examples/*.md5",
    "auto_examples/*.pickle",
]

# -- autodoc, autosummary, numpydoc -----------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "signature"
autodoc_preserve_defaults = True
# a method without a docstring of its own (``step`` of an env) shows none, rather than the
# Gymnasium base class's, which is not numpydoc
autodoc_inherit_docstrings = False
# the reference builds without the ``rl`` extra too: Stable-Baselines3 (the base class of
# ``shipgym.rl.ShipgymVecEnv``) is then a stand-in
autodoc_mock_imports = (
    [] if importlib.util.find_spec("stable_baselines3") else ["stable_baselines3"]
)
# the class stubs list their own methods and attributes (templates in _templates/autosummary)
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True

# -- Markdown ---------------------------------------------------------------------------------
myst_enable_extensions = ["colon_fence", "dollarmath", "deflist"]
# ``[Speed](#speed)``-style links between and within pages
myst_heading_anchors = 3

# -- Gallery ----------------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples" / "gallery"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "image_scrapers": ("matplotlib",),
    "reset_modules": ("matplotlib",),
    "remove_config_comments": True,
    "download_all_examples": False,
    "show_memory": False,
    "min_reported_time": 1.0,
    # an example that fails is a build error, not a warning in the page
    "abort_on_example_error": True,
}

# -- HTML -------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"shipgym {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "header_links_before_dropdown": 5,
}
html_show_sourcelink = False


# -- Docstrings as written in the source ------------------------------------------------------
# The environments' docstrings follow Gymnasium's (``## Description``, ``## Action Space``, ...,
# with Markdown tables), so that ``help(env)`` reads well in a terminal; the page shows the
# same text with its headings as rubrics and its tables as tables. A constant's page shows the
# ``#:`` comment above it in the module that defines it (also when a package re-exports it)
# and, when it is short, its value; never the docstring of its type (``tuple``, ``dict``).

_MD_HEADING = re.compile(r"^(\s*)#{2,6}\s+(\S.*?)\s*$")
_MD_RULE = re.compile(r"^\s*\|(\s*:?-{3,}:?\s*\|)+\s*$")
_MD_ROW = re.compile(r"^\s*\|.*\|\s*$")
_MAX_VALUE_CHARS = 100


def _cells(row: str) -> list[str]:
    """The cells of a Markdown table row; a ``|`` inside an inline literal is text."""
    cells, cell, literal, i = [], "", False, 0
    body = row.strip()[1:-1]
    while i < len(body):
        if body.startswith("``", i):
            literal = not literal
            cell += "``"
            i += 2
            continue
        if body[i] == "|" and not literal:
            cells.append(cell.strip())
            cell = ""
        else:
            cell += body[i]
        i += 1
    cells.append(cell.strip())
    return cells


def _markdown_to_rst(lines: list[str]) -> list[str]:
    """Markdown headings and pipe tables in ``lines`` as reStructuredText."""
    out: list[str] = []
    i = 0
    while i < len(lines):
        line = lines[i]
        heading = _MD_HEADING.match(line)
        if heading:
            out += [f"{heading.group(1)}.. rubric:: {heading.group(2)}", ""]
            i += 1
            continue
        if _MD_ROW.match(line) and i + 1 < len(lines) and _MD_RULE.match(lines[i + 1]):
            indent = line[: len(line) - len(line.lstrip())]
            rows = [_cells(line)]
            i += 2
            while i < len(lines) and _MD_ROW.match(lines[i]):
                rows.append(_cells(lines[i]))
                i += 1
            out += ["", f"{indent}.. list-table::", f"{indent}   :header-rows: 1", ""]
            for row in rows:
                first, *rest = row
                out.append(f"{indent}   * - {first}")
                out += [f"{indent}     - {cell}" for cell in rest]
            out.append("")
            continue
        out.append(line)
        i += 1
    return out


def _comment_doc(name: str, obj: Any) -> list[str]:
    """The ``#:`` comment of the constant ``name`` in the module that defines it."""
    from sphinx.pycode import ModuleAnalyzer

    modname, attr = name.rsplit(".", 1)
    for candidate in sorted(m for m in sys.modules if m == modname or m.startswith(modname + ".")):
        module = sys.modules[candidate]
        if getattr(module, attr, None) is not obj:
            continue
        try:
            docs = ModuleAnalyzer.for_module(candidate).find_attr_docs()
        except Exception:  # a module without source (a compiled extension)
            continue
        if ("", attr) in docs:
            return [line for line in docs["", attr] if line is not None]
    return []


def _text(lines: list[str]) -> list[str]:
    return [line.strip() for line in lines if line.strip()]


def _process_docstring(
    app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]
) -> None:
    if what in ("data", "attribute") and not callable(obj):
        if _text(lines) == _text((inspect.getdoc(type(obj)) or "").splitlines()):
            lines[:] = _comment_doc(name, obj) if what == "data" else []
        if what == "data":
            value = repr(obj)
            if len(value) <= _MAX_VALUE_CHARS and "``" not in value:
                lines += ["", f":Value: ``{value}``"]
    lines[:] = _markdown_to_rst(lines)


def setup(app: Any) -> None:
    # before numpydoc (priority 500), so that it parses the converted text
    app.connect("autodoc-process-docstring", _process_docstring, priority=400)
