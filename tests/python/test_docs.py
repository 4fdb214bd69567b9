# SPDX-License-Identifier: MIT
"""Every public Python function has a numpy-style docstring, and the API documentation
builds from them with pdoc, without network."""
from __future__ import annotations

import importlib
import inspect
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

#: Modules whose public names (``__all__``) are documented.
MODULES = ["yarnfort", "yarnfort.address", "yarnfort.namelist", "yarnfort.results",
           "yarnfort.runner", "yarnfort.scene", "yarnfort.sweep", "yarnfort.calibrate",
           "yarnfort.plots", "yarnfort.units", "yarnfort.fabric_export"]


def public_callables():
    for name in MODULES:
        module = importlib.import_module(name)
        for attr in module.__all__:
            obj = getattr(module, attr)
            if inspect.isclass(obj):
                yield f"{name}.{attr}", obj
                for member, function in vars(obj).items():
                    if not member.startswith("_") and inspect.isfunction(function):
                        yield f"{name}.{attr}.{member}", function
            elif callable(obj):
                yield f"{name}.{attr}", obj


def test_public_functions_have_numpy_docstrings():
    problems = []
    for label, obj in public_callables():
        doc = inspect.getdoc(obj) or ""
        if not doc:
            problems.append(f"{label}: no docstring")
            continue
        if inspect.isclass(obj):
            continue
        parameters = [p for p in inspect.signature(obj).parameters if p not in ("self", "cls")]
        if parameters and "Parameters\n----------" not in doc:
            problems.append(f"{label}: no Parameters section")
    assert not problems, "\n".join(problems)


def test_api_docs_build_offline(tmp_path):
    pytest.importorskip("pdoc")
    # No proxy and an unroutable one: any network access would fail the build.
    env = dict(os.environ, http_proxy="http://0.0.0.0:9", https_proxy="http://0.0.0.0:9",
               MPLBACKEND="Agg")
    run = subprocess.run([sys.executable, "-m", "pdoc", "--docformat", "numpy", "--no-search",
                          "--output-directory", str(tmp_path), *MODULES],
                         capture_output=True, text=True, env=env, timeout=300)
    assert run.returncode == 0, run.stderr
    page = (tmp_path / "yarnfort" / "scene.html").read_text()
    assert "add_material" in page and "Parameters" in page
    runner = (tmp_path / "yarnfort" / "runner.html").read_text()
    assert "RunInterrupted" in runner and "step boundary" in runner


def _github_anchor(heading: str) -> str:
    """The anchor GitHub gives a Markdown heading: lowercase, punctuation dropped,
    spaces as hyphens."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def test_relative_markdown_links_resolve():
    """Every relative link and image of the tracked Markdown files names a file that
    exists, and a #fragment a heading of it."""
    top = Path(__file__).resolve().parents[2]
    listed = subprocess.run(["git", "ls-files", "*.md"], cwd=top, capture_output=True,
                            text=True)
    if listed.returncode != 0:
        pytest.skip("not a git checkout")
    link = re.compile(r"\]\(([^)\s]+)\)|<img src=\"([^\"]+)\"")
    problems = []
    for name in listed.stdout.split():
        page = top / name
        for match in link.finditer(page.read_text()):
            target = match.group(1) or match.group(2)
            if re.match(r"[a-z][a-z0-9+.-]*:", target):
                continue  # https:, mailto: ...
            path, _, fragment = target.partition("#")
            linked = (page.parent / path) if path else page
            if not linked.exists():
                problems.append(f"{name}: {target}: no such file")
            elif fragment and linked.suffix == ".md":
                headings = re.findall(r"^#+ (.+)$", linked.read_text(), re.MULTILINE)
                if fragment not in {_github_anchor(h) for h in headings}:
                    problems.append(f"{name}: {target}: no such heading")
    assert not problems, "\n".join(problems)
