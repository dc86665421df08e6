"""The project names no path of a particular machine and no file outside the repository.

Scans every file git tracks (text files only): no absolute home, temporary or workspace paths, no files the
repository does not hold (the paper's transcription sheets, notes), every Markdown link and every
backticked repository path in docs and code names a tracked file, and every link's ``#anchor`` a heading of the
page. The paper is cited by its equation, table and section numbers instead.
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: an absolute path into a home, temporary or workspace folder (a Unix path, or a Windows drive)
MACHINE_PATH = re.compile(r"(?<![\w.~-])/(?:work|tmp|root|home|Users|mnt|opt|srv|var/folders)/[\w.-]"
                          r"|\b[A-Z]:\\{1,2}(?:Users|Documents and Settings)\\")
#: files that are not in the repository but were once cited as if they were (spelled in pieces, so that this
#: file does not match itself)
OUTSIDE = re.compile("|".join(re.escape(a + b) for a, b in (
    ("CASE-", "STUDY.md"), ("EQUA", "TIONS.md"), ("shared/", "paper"), ("shared/", "notes"), ("/no", "tes/"))))
#: a Markdown link to a relative target
LINK = re.compile(r"\]\(([^)\s#]+)(?:#[^)]*)?\)")
#: a backticked repository-relative path with a file ending
REPO_PATH = re.compile(r"`([\w.-]+(?:/[\w.-]+)+\.(?:py|md|toml|csv|json|txt))`")
#: where runs write by default: a path there names an output, not a repository file
OUTPUT_PREFIXES = ("apexseal-out/",)


def _tracked() -> list[str]:
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout: the tracked files are unknown")
    return [f for f in out.split("\0") if f]


def _texts():
    for name in _tracked():
        path = ROOT / name
        if not path.is_file():
            continue
        data = path.read_bytes()
        if b"\0" in data:
            continue
        try:
            yield name, data.decode("utf-8")
        except UnicodeDecodeError:
            continue


def test_no_machine_paths_or_outside_files():
    found = []
    for name, text in _texts():
        for i, line in enumerate(text.splitlines(), 1):
            for pattern, what in ((MACHINE_PATH, "machine path"), (OUTSIDE, "file outside the repository")):
                m = pattern.search(line)
                if m:
                    found.append(f"{name}:{i}: {what} {m.group(0)!r}")
    assert not found, "cite the paper (equation, table, section) or keep the file in the repository:\n" + "\n".join(found)


def test_links_and_repository_paths_name_tracked_files():
    tracked = set(_tracked())
    folders = {str(Path(f).parent.as_posix()) for f in tracked}
    missing = []
    for name, text in _texts():
        if name.startswith("generated/default/"):
            continue
        if name.endswith(".md"):
            for m in LINK.finditer(text):
                target = m.group(1)
                if re.match(r"^[a-z]+:", target):
                    continue
                rel = os.path.normpath(Path(name).parent / target)
                if rel not in tracked and rel not in folders:
                    missing.append(f"{name}: link ({target}) names no tracked file")
        if name.endswith((".md", ".py", ".toml")):
            for m in REPO_PATH.finditer(text):
                path = m.group(1)
                if path not in tracked and not path.startswith(OUTPUT_PREFIXES):
                    missing.append(f"{name}: `{path}` is not in the repository")
    assert not missing, "\n".join(missing)


#: a Markdown link with a fragment: (file, anchor); an empty file is the page itself
ANCHORED_LINK = re.compile(r"\]\(([^)\s#]*)#([^)\s]+)\)")
#: a fenced code block (its lines are neither headings nor links)
FENCE = re.compile(r"^(```|~~~).*?^\1[^\n]*$", re.M | re.S)


def heading_anchors(markdown: str) -> set[str]:
    """The anchors a Markdown page gets from its headings, as GitHub makes them: lower case, inline markup and
    punctuation dropped (letters of any script, digits, ``_`` and ``-`` kept), each space a hyphen, and a repeated
    heading numbered ``-1``, ``-2``, ...; headings inside fenced code blocks are not headings."""
    anchors: set[str] = set()
    seen: dict[str, int] = {}
    for line in FENCE.sub("", markdown).splitlines():
        m = re.match(r" {0,3}#{1,6}\s+(.*?)(?:\s+#+)?\s*$", line)
        if not m:
            continue
        slug = re.sub(r"[^\w\- ]", "", re.sub(r"<[^>]*>", "", m.group(1)).lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        anchors.add(slug if n == 0 else f"{slug}-{n}")
    return anchors


def dead_anchors(name: str, text: str, pages: dict[str, str]) -> list[str]:
    """The links of the page ``name`` (text ``text``) whose ``#anchor`` is no heading of the Markdown page they
    name (``pages``: path -> text)."""
    dead = []
    for m in ANCHORED_LINK.finditer(FENCE.sub("", text)):
        target, anchor = m.groups()
        if re.match(r"^[a-z]+:", target):
            continue
        page = os.path.normpath(Path(name).parent / target) if target else name
        if page.endswith(".md") and page in pages and anchor not in heading_anchors(pages[page]):
            dead.append(f"{name}: link ({target}#{anchor}) names no heading of {page}")
    return dead


def test_links_to_a_heading_name_a_heading_that_exists():
    """A link to ``page.md#anchor`` (or ``#anchor`` on the same page) lands on a heading: a heading renamed without
    its links left them pointing at the top of the page."""
    pages = {name: text for name, text in _texts() if name.endswith(".md")}
    assert sum(len(ANCHORED_LINK.findall(t)) for t in pages.values()) > 10  # the pattern still finds the links
    dead = [d for name, text in pages.items() for d in dead_anchors(name, text, pages)]
    assert not dead, "\n".join(dead)


def test_the_anchor_rules_are_githubs():
    page = ("# Bad input → what you get\n## `[machine]` — the limaçon (Eqs. 1–8)\n## Notes\n## Notes\n"
            "```\n# not a heading\n```\n")
    assert heading_anchors(page) == {"bad-input--what-you-get", "machine--the-limaçon-eqs-18", "notes", "notes-1"}
    pages = {"docs/a.md": page, "docs/b.md": "[x](a.md#notes-1) [y](a.md#not-a-heading) [z](#nowhere) [w](../README.md#q)"}
    assert dead_anchors("docs/b.md", pages["docs/b.md"], pages) == [
        "docs/b.md: link (a.md#not-a-heading) names no heading of docs/a.md",
        "docs/b.md: link (#nowhere) names no heading of docs/b.md"]


@pytest.mark.parametrize(("line", "hit"), [
    # the examples are spelled in pieces, so that this file does not match itself
    ("see /ho" + "me/alice/seal.toml", True), ('"scene": "/t' + 'mp/x/default.toml"', True), ("C:" + "\\Users\\me", True),
    ("C:" + "\\\\Users\\\\me", True),
    ("CASE-" + "STUDY.md", True), ("runtime/scenes/default.toml", False), ("Eq. 9 and Table 1", False),
    ('needles = ["/ho' + 'me/", "/ro' + 'ot"]', False), ("a/b/" + "work/c", False),
])
def test_the_patterns_catch_what_they_are_for(line, hit):
    assert bool(MACHINE_PATH.search(line) or OUTSIDE.search(line)) is hit
