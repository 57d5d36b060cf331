"""Every command shown in the README and the docs runs, in the order shown, on a clean
folder holding only the repository's examples."""

from __future__ import annotations

import os
import re
import shlex
from pathlib import Path

import pytest
from click.testing import CliRunner

from holoradar.app.cli import main

REPO = Path(__file__).resolve().parents[1]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
_BLOCK = re.compile(r"```console\n(.*?)```", re.S)


def commands(page: Path) -> list[list[str]]:
    """The ``$ holoradar ...`` lines of a page's console blocks."""
    out = []
    for block in _BLOCK.findall(page.read_text()):
        for line in block.splitlines():
            if line.startswith("$ holoradar "):
                out.append(shlex.split(line[len("$ holoradar "):]))
    return out


def test_the_pages_show_commands():
    assert sum(len(commands(p)) for p in PAGES) >= 10
    assert commands(REPO / "README.md")


@pytest.mark.parametrize("page", [p for p in PAGES if commands(p)], ids=lambda p: p.name)
def test_every_documented_command_runs(page, tmp_path, monkeypatch):
    (tmp_path / "examples").symlink_to(REPO / "examples")
    monkeypatch.chdir(tmp_path)
    for args in commands(page):
        res = CliRunner().invoke(main, [*args, "--quiet"] if args[0] != "demo" else
                                 [*args, "--upsample", "2", "--quiet"])
        assert res.exit_code == 0, f"holoradar {' '.join(args)}\n{res.output}"
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]
