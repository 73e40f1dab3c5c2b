"""The API reference (``docs/reference/api.rst``) lists every public name of the packages.

The public names of a module are its ``__all__``; a module without one exports the functions
and classes it defines whose names do not start with ``_``. A name is listed either in its own
module's section or, when a package re-exports it in its ``__all__``, in the section of that
package. The sources are read, not imported, so the check runs without the optional extras
(``shipgym.rl`` needs the ``rl`` extra to import). The command line (``shipgym.cli``) has its
own page, generated from its parser (``docs/reference/cli.rst``).
"""

from __future__ import annotations

import ast
import functools
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
API = ROOT / "docs" / "reference" / "api.rst"
PACKAGES = ("shipgym", "controllers")
NOT_IN_API = ("shipgym.cli",)


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def public_modules() -> dict[str, Path]:
    """Every importable module of the packages whose dotted name has no ``_`` part."""
    modules = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            name = _module_name(path)
            private = any(part.startswith("_") for part in name.split("."))
            elsewhere = any(name == m or name.startswith(m + ".") for m in NOT_IN_API)
            if not private and not elsewhere:
                modules[name] = path
    return modules


@functools.cache
def public_names(path: Path) -> list[str]:
    """``__all__`` of the module at ``path``, or its public top-level functions and classes."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in tree.body:
        targets = (
            node.targets
            if isinstance(node, ast.Assign)
            else [node.target]
            if isinstance(node, ast.AnnAssign) and node.value is not None
            else []
        )
        if any(isinstance(t, ast.Name) and t.id == "__all__" for t in targets):
            return list(ast.literal_eval(node.value))
    return [
        node.name
        for node in tree.body
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef)
        and not node.name.startswith("_")
    ]


def reference() -> tuple[set[str], set[str]]:
    """The module pages and the documented ``module.name`` entries of ``api.rst``.

    The entries of an ``autosummary`` directive before the first ``currentmodule`` are module
    names (the module pages); after it, names in the current module.
    """
    modules: set[str] = set()
    entries: set[str] = set()
    current = None
    in_summary = False
    for line in API.read_text(encoding="utf-8").splitlines():
        if match := re.match(r"\.\. currentmodule:: (\S+)", line):
            current = match.group(1)
            in_summary = False
        elif line.startswith(".. autosummary::"):
            in_summary = True
        elif in_summary and re.match(r"   \S", line) and not line.lstrip().startswith(":"):
            name = line.strip()
            if current is None:
                modules.add(name)
            else:
                entries.add(f"{current}.{name}")
        elif line and not line.startswith(" "):
            in_summary = False
    return modules, entries


MODULES = public_modules()
PAGES, ENTRIES = reference()


def test_the_walk_finds_the_packages() -> None:
    assert {"shipgym", "shipgym.envs", "shipgym.sysid.io", "controllers"} <= set(MODULES)
    assert "NomotoHeadingEnv" in public_names(MODULES["shipgym.envs"])
    assert len(ENTRIES) > 300


def test_every_public_module_has_a_page() -> None:
    missing = sorted(set(MODULES) - PAGES)
    assert not missing, f"modules without a page in {API.name}'s module list: {missing}"


@pytest.mark.parametrize("module", sorted(MODULES))
def test_every_public_name_is_in_the_reference(module: str) -> None:
    parts = module.split(".")
    ancestors = [".".join(parts[:i]) for i in range(1, len(parts))]
    missing = []
    for name in public_names(MODULES[module]):
        homes = [module] + [
            p for p in ancestors if p in MODULES and name in public_names(MODULES[p])
        ]
        if f"{module}.{name}" in MODULES:  # a submodule listed in its package's __all__
            homes = []
        if homes and not any(f"{home}.{name}" in ENTRIES for home in homes):
            missing.append(name)
    assert not missing, (
        f"public names of {module} not in {API.relative_to(ROOT)}: {missing} (add them to the "
        f"autosummary of {module}, or of the package that re-exports them)"
    )


def test_every_entry_is_a_public_name() -> None:
    stale = []
    for entry in sorted(ENTRIES):
        module, name = entry.rsplit(".", 1)
        if module not in MODULES or name not in public_names(MODULES[module]):
            stale.append(entry)
    assert not stale, f"entries of {API.name} that are no public name of their module: {stale}"
