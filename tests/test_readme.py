"""The README and the documentation pages: short, linked, and in step with CI.

* the README is at most :data:`README_MAX_LINES` lines: the rest lives in ``docs/``;
* every relative link, image and MyST ``{include}`` in ``README.md`` and ``docs/**/*.md`` points
  at a file that exists (external links and in-page anchors are not followed);
* the README's Quickstart holds exactly two commands, the second being what ``.ci/run`` runs;
* no page speaks of issue numbers.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
README_MAX_LINES = 300
QUICKSTART = (
    'pip install ".[rl]" && shipgym benchmark',
    'pip install ".[dev]" && python -m pytest',
)

#: ``[text](target)`` and ``![alt](target)``, with an optional title after the target.
_LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
_INLINE_CODE = re.compile(r"`[^`]*`")
_ISSUE = re.compile(r"\bissues?\s*(?:no\.?\s*)?#?\d+|(?<![\w&/])#\d+\b", re.IGNORECASE)


def pages() -> list[Path]:
    """The README and every Markdown page under ``docs/`` (not the built site)."""
    found = sorted(p for p in DOCS.rglob("*.md") if "_build" not in p.relative_to(DOCS).parts)
    return [README, *found]


def _prose_and_includes(text: str) -> tuple[str, list[str]]:
    """The text outside fenced code blocks, and the targets of MyST ``{include}`` fences."""
    prose, includes, fence = [], [], None
    for line in text.splitlines():
        stripped = line.strip()
        if fence is None and stripped.startswith(("```", "~~~")):
            fence = stripped[:3]
            match = re.match(r"[`~]{3,}\{include\}\s+(\S+)", stripped)
            if match:
                includes.append(match.group(1))
            continue
        if fence is not None:
            if stripped.startswith(fence):
                fence = None
            continue
        prose.append(line)
    return "\n".join(prose), includes


def relative_targets(page: Path) -> list[str]:
    """The relative link, image and include targets of ``page``, without their anchors."""
    prose, includes = _prose_and_includes(page.read_text(encoding="utf-8"))
    links = _LINK.findall(_INLINE_CODE.sub("", prose))
    targets = []
    for target in [*links, *includes]:
        if re.match(r"[a-z][a-z0-9+.-]*:", target, re.IGNORECASE) or target.startswith("#"):
            continue  # http(s), mailto, an anchor in the same page
        targets.append(target.split("#", 1)[0])
    return targets


def quickstart_commands(text: str) -> list[str]:
    """The shell commands of the README's Quickstart section (continuation lines joined)."""
    match = re.search(r"^## Quickstart\n(.*?)(?=^## )", text, re.MULTILINE | re.DOTALL)
    assert match, "README has no '## Quickstart' section followed by another section"
    blocks = re.findall(r"^```(?:bash|sh|shell|console)?\n(.*?)^```", match.group(1),
                        re.MULTILINE | re.DOTALL)  # fmt: skip
    commands = []
    for block in blocks:
        joined = re.sub(r"\\\n\s*", "", block)
        commands += [c.strip() for c in joined.splitlines() if c.strip() and not c.startswith("#")]
    return commands


def ci_commands() -> list[str]:
    """The lines ``.ci/run`` executes (comments and blank lines left out)."""
    lines = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    return [line.strip() for line in lines if line.strip() and not line.strip().startswith("#")]


def test_readme_is_short() -> None:
    n = len(README.read_text(encoding="utf-8").splitlines())
    assert n <= README_MAX_LINES, f"README.md has {n} lines, expected at most {README_MAX_LINES}"


def test_the_link_checker_sees_links_images_and_includes(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text(
        'See [the guide](guide/a.md#part) and ![fig](../b.png "title"), not '
        "[the web](https://example.org) nor [here](#here) nor `[code](c.md)`.\n\n"
        "```python\nx = '[in code](d.md)'\n```\n\n```{include} ../e.md\n:heading-offset: 1\n```\n"
    )
    assert relative_targets(page) == ["guide/a.md", "../b.png", "../e.md"]


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_resolve(page: Path) -> None:
    missing = [t for t in relative_targets(page) if not (page.parent / t).exists()]
    assert not missing, f"{page.relative_to(ROOT)} links to missing files: {missing}"


def test_every_guide_and_results_page_exists() -> None:
    expected = {
        "guide": ["install", "envs", "models", "controllers", "benchmark", "training",
                  "identification", "your_data", "ray", "data", "limitations"],
        "results": ["speed", "gunnerus", "kvlcc2", "benchmark", "identification"],
    }  # fmt: skip
    for folder, names in expected.items():
        for name in names:
            page = DOCS / folder / f"{name}.md"
            assert page.is_file(), f"missing page {page.relative_to(ROOT)}"
            first = page.read_text(encoding="utf-8").splitlines()[0]
            assert first.startswith("# "), f"{page.relative_to(ROOT)} starts without a title"


def test_quickstart_has_the_two_commands_ci_runs() -> None:
    commands = quickstart_commands(README.read_text(encoding="utf-8"))
    assert commands == list(QUICKSTART), f"the Quickstart's commands are {commands}"
    assert commands[1] in ci_commands(), f".ci/run does not run {commands[1]!r}"


def test_quickstart_parser_joins_continuations() -> None:
    text = "## Quickstart\n\n```bash\n# comment\npip install . \\\n    && pytest\n```\n\n## Next\n"
    assert quickstart_commands(text) == ["pip install . && pytest"]


@pytest.mark.parametrize("page", pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_page_mentions_issue_numbers(page: Path) -> None:
    hits = _ISSUE.findall(page.read_text(encoding="utf-8"))
    assert not hits, f"{page.relative_to(ROOT)} mentions issue numbers: {hits}"


def test_issue_pattern() -> None:
    assert _ISSUE.findall("fixed in issue 29, see #12 and Issue #3")
    assert not _ISSUE.findall("seed 001, 20/20 zigzag, `# L: 7.0`, C# code, a/#1 path, &#8212;")


def test_relative_link_from_a_page_to_a_figure() -> None:
    """The scripts link their figures from the page that shows them (``shipgym.sysid.report``)."""
    from shipgym.sysid.report import relative_link

    assert relative_link("docs/training.png", "docs/guide/training.md") == "../training.png"
    assert relative_link(DOCS / "benchmark", DOCS / "results" / "benchmark.md") == "../benchmark"
    assert relative_link(DOCS / "gunnerus_loop.png", DOCS / "gunnerus.md") == "gunnerus_loop.png"
