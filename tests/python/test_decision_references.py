# SPDX-License-Identifier: MIT
"""Every reference to an entry of docs/decisions.md names an entry that is there.

Code comments keep the rule and name the entry with the measurements (docs/decisions.md,
"Heading"); a reference whose entry was renamed or lost in a merge sends the reader to
nothing."""
from __future__ import annotations

import re
from pathlib import Path

TOP = Path(__file__).resolve().parents[2]
DECISIONS = TOP / "docs" / "decisions.md"
#: Where references live: sources, scripts, documents, inputs.
FOLDERS = ["src", "python", "benchmarks", "tools", "tests", "verification", "docs", "inputs"]
SUFFIXES = {".f90", ".py", ".c", ".md", ".nml", ".build", ""}
#: A comment's continuation marker at the start of a line (Fortran, Python, C).
CONTINUATION = re.compile(r"\n[ \t]*(?:!>?|#:?|//|\*)?[ \t]*")
#: `decisions.md, "Heading"` or `decisions.md "Heading"`, and within decisions.md the
#: entries quoted as ("Heading").
REFERENCE = re.compile(r'decisions\.md,?\s+"([^"]+)"')
SELF_REFERENCE = re.compile(r'\("([A-Z][^"]+)"\)')


def headings():
    return [line[3:].strip() for line in DECISIONS.read_text().splitlines()
            if line.startswith("## ")]


def names_an_entry(name, titles):
    """A reference may quote a heading whole or its beginning (headings carry issue tags
    and qualifiers the comments leave out)."""
    name = " ".join(name.split())
    return any(title.startswith(name) for title in titles)


def text_of(path):
    return CONTINUATION.sub(" ", path.read_text(errors="replace"))


def files():
    for folder in FOLDERS:
        for path in sorted((TOP / folder).rglob("*")):
            if path.is_file() and path.suffix in SUFFIXES and "build" not in path.parts \
                    and path != Path(__file__).resolve():
                yield path


def test_references_name_existing_entries():
    titles = headings()
    assert len(titles) > 50, "docs/decisions.md has lost its entries"
    dangling = []
    for path in files():
        text = text_of(path)
        found = REFERENCE.findall(text)
        if path == DECISIONS:
            found += SELF_REFERENCE.findall(text)
        for name in found:
            if not names_an_entry(name, titles):
                dangling.append(f"{path.relative_to(TOP)}: {name!r}")
    assert not dangling, "references to no entry of docs/decisions.md:\n" + "\n".join(dangling)


def test_the_check_finds_a_dangling_reference(tmp_path):
    # The pattern must see a reference split over comment lines, as the code writes them.
    source = tmp_path / "x.f90"
    source.write_text('! rule (docs/decisions.md, "A slip away from a\n'
                      '! lock it never reached"); and "No such entry" (docs/decisions.md,\n'
                      '! "No such\n!> entry").\n')
    titles = headings()
    found = REFERENCE.findall(text_of(source))
    assert [names_an_entry(name, titles) for name in found] == [True, False]
