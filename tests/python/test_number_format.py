# SPDX-License-Identifier: MIT
"""Numbers in messages (issue 42): no ES, EN, E or D edit descriptor without an exponent
width in the Fortran sources. Such a descriptor drops the exponent letter of a
three-digit exponent (gfortran writes 1.8e308 in es9.2 as '1.80+308'); messages use
yarnfort_text's format_short, whose output is checked in tests/unit/text."""
from __future__ import annotations

import re
from pathlib import Path

TOP = Path(__file__).resolve().parents[2]
#: An edit descriptor such as es9.2, e12.4 or d10.3 not followed by an exponent width.
NO_EXPONENT_WIDTH = re.compile(r"(?i)(?<![\w%.])(?:es|en|e|d)\d+\.\d+(?!\d|e\d)")


def character_literals(source: str) -> list[tuple[int, str]]:
    """The character literals of Fortran free-form source with the line each starts on,
    continued literals ('...&' / '&...') joined; comments skipped."""
    literals, quote, text, start = [], "", "", 0
    for number, line in enumerate(source.splitlines(), start=1):
        i = 0
        if quote:                       # a literal continued: it resumes after '&'
            stripped = line.lstrip()
            if stripped.startswith("!") or not stripped:
                continue
            i = len(line) - len(stripped) + (1 if stripped.startswith("&") else 0)
        while i < len(line):
            c = line[i]
            if quote:
                if c == quote and line[i + 1:i + 2] == quote:
                    text += c
                    i += 2
                    continue
                if c == quote:
                    literals.append((start, text))
                    quote = ""
                elif c == "&" and not line[i + 1:].strip():
                    break                   # continued on the next line
                else:
                    text += c
            elif c == "!":
                break
            elif c in "'\"":
                quote, text, start = c, "", number
            i += 1
    return literals


def test_no_exponent_descriptor_without_exponent_width():
    found = [f"{path.relative_to(TOP)}:{number}: {text}"
             for path in sorted((TOP / "src").rglob("*.f90"))
             for number, text in character_literals(path.read_text())
             if NO_EXPONENT_WIDTH.search(text)]
    assert not found, "\n".join(found)


def test_literals_are_found_across_continuations():
    source = ("x = 1 ! it's a comment with es9.2\n"
              "write(b, '(\"a \", es9.2, &\n"
              "    ! a comment line between\n"
              "    &\" b\")') y\n"
              "c = \"it''s\"\n")
    assert character_literals(source) == [(2, '("a ", es9.2, " b")'), (5, "it''s")]
