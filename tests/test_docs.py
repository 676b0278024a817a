"""The documentation describes the present, in pages a reader can hold, and points at real files.

- every relative link in README.md and docs/*.md, and every repository path written in code
  spans (``docs/…``, ``benchmarks/…``, ``scenes/…``, ``studies/…``, ``scripts/…``,
  ``sandwich/…``, dotted ``sandwich.…`` modules), exists; a module under ``sandwich/`` may be
  cited as a file or as a package (``sandwich/x/y.py`` and ``sandwich/x/y/`` are one name);
- docs/ is at most 3000 lines in all and no page above 320;
- no dated narrative ("since 2026-…", "session", "was … before", a superseded decision) and no
  journal: history lives in git, the pages say what holds now.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]
MAX_TOTAL, MAX_PAGE = 3000, 320
PREFIXES = ("docs/", "benchmarks/", "scenes/", "studies/", "scripts/", "sandwich/")
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
CODE = re.compile(r"`([^`\n]+)`")
FENCED = re.compile(r"^```.*?^```", re.MULTILINE | re.DOTALL)
MODULE = re.compile(r"^sandwich(\.[A-Za-z_][A-Za-z0-9_]*)+")
NARRATIVE = {
    "a 'since <date>'": re.compile(r"\bsince 20\d\d-\d\d", re.IGNORECASE),
    "an 'until <date>'": re.compile(r"\buntil 20\d\d-\d\d-\d\d", re.IGNORECASE),
    "a session": re.compile(r"\bsessions?\b", re.IGNORECASE),
    "a 'was … before'": re.compile(r"\bwas\b[^.\n]{0,80}\bbefore\b", re.IGNORECASE),
    "a '(was …)'": re.compile(r"\(was\b", re.IGNORECASE),
    "a superseded decision": re.compile(r"\bsuperseded\b", re.IGNORECASE),
    "'used to be'": re.compile(r"\bused to be\b", re.IGNORECASE),
}


def _text(page: Path) -> str:
    return page.read_text(encoding="utf-8")


def _name(page: Path) -> str:
    return str(page.relative_to(ROOT))


def exists_in_repo(path: str) -> bool:
    """``path`` (relative to the repository) exists; globs match something; a module under
    ``sandwich/`` counts as present as ``x.py`` or as the package ``x/``."""
    path = path.rstrip(".,;:)")
    if any(c in path for c in "*?["):
        return any(ROOT.glob(path))
    target = ROOT / path
    if target.exists():
        return True
    if path.startswith("sandwich/"):
        stem = path.rstrip("/")
        return (ROOT / f"{stem.removesuffix('.py')}.py").is_file() or \
            (ROOT / stem.removesuffix(".py")).is_dir()
    return False


def module_exists(dotted: str) -> bool:
    """``sandwich.a.b…``: ``sandwich/a`` resolves to a module or package; further names are
    followed while they are modules (the rest are attributes)."""
    parts = dotted.split(".")[1:]
    here = ROOT / "sandwich"
    for i, part in enumerate(parts):
        if (here / part).is_dir():
            here = here / part
        elif (here / f"{part}.py").is_file():
            return True
        else:
            return i > 0
    return True


def repo_paths(text: str) -> list[str]:
    """Repository paths written in code spans (each whitespace-separated token checked)."""
    text = FENCED.sub("", text)
    found = []
    for span in CODE.findall(text):
        for token in span.split():
            token = token.strip("\"'(),;")
            if token.startswith(PREFIXES) and "<" not in token and "…" not in token:
                found.append(token)
    return found


def modules(text: str) -> list[str]:
    """Dotted ``sandwich.…`` names written in code spans."""
    out = []
    for span in CODE.findall(FENCED.sub("", text)):
        m = MODULE.match(span.strip())
        if m:
            out.append(m.group(0))
    return out


@pytest.mark.parametrize("page", PAGES, ids=_name)
def test_relative_links_resolve(page):
    broken = []
    for target in LINK.findall(_text(page)):
        if re.match(r"^[a-z]+:", target) or target.startswith("#"):
            continue
        if not (page.parent / target.split("#", 1)[0]).exists():
            broken.append(target)
    assert broken == [], f"{_name(page)}: links to missing files: {broken}"


@pytest.mark.parametrize("page", PAGES, ids=_name)
def test_repository_paths_exist(page):
    missing = [p for p in repo_paths(_text(page)) if not exists_in_repo(p)]
    missing += [m for m in modules(_text(page)) if not module_exists(m)]
    assert missing == [], f"{_name(page)}: names no such file or module: {missing}"


def test_docs_are_short_pages():
    sizes = {_name(p): len(_text(p).splitlines()) for p in DOCS.glob("*.md")}
    assert sum(sizes.values()) <= MAX_TOTAL, sizes
    assert {k: n for k, n in sizes.items() if n > MAX_PAGE} == {}


def test_no_journal():
    assert not (DOCS / "journal").exists()


@pytest.mark.parametrize("page", PAGES, ids=_name)
def test_no_dated_narrative(page):
    hits = [f"{what}: {m.group(0)!r}" for what, rx in NARRATIVE.items()
            for m in rx.finditer(_text(page))]
    assert hits == [], f"{_name(page)} tells history (it belongs in git): {hits}"


def test_the_path_checks_can_fail():
    assert not exists_in_repo("docs/no_such_page.md")
    assert exists_in_repo("sandwich/solver/") and exists_in_repo("sandwich/cli.py")
    assert not module_exists("sandwich.beam_element") and module_exists("sandwich.beam.run")
    assert repo_paths("see `benchmarks/results/x.md` and `results/<scene>/`") == [
        "benchmarks/results/x.md"]
    assert NARRATIVE["a 'since <date>'"].search("moved since 2026-12-05 …")
