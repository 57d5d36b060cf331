"""Every command shown in the README and the docs runs, in the order shown, on a clean
folder holding only the repository's examples."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from holoradar.app.cli import main

REPO = Path(__file__).resolve().parents[1]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
_BLOCK = re.compile(r"```console\n(.*?)```", re.S)


def commands(page: Path) -> list[list[str]]:
    """The ``$ holoradar ...`` and ``$ python ...`` lines of a page's console blocks."""
    out = []
    for block in _BLOCK.findall(page.read_text()):
        for line in block.splitlines():
            if line.startswith("$ holoradar "):
                out.append(shlex.split(line[len("$ holoradar "):]))
            elif line.startswith("$ python "):
                out.append(["python", *shlex.split(line[len("$ python "):])])
    return out


def test_the_pages_show_commands():
    assert sum(len(commands(p)) for p in PAGES) >= 10
    assert commands(REPO / "README.md")


# The pages whose commands take several seconds end to end (each command is also tested
# on its own in test_cli_commands.py): run with make test-slow.
_LONG_PAGES = {"cli.md", "viewer.md", "surveys.md", "inversion.md"}


@pytest.mark.parametrize("page", [pytest.param(p, marks=pytest.mark.slow)
                                  if p.name in _LONG_PAGES else p
                                  for p in PAGES if commands(p)], ids=lambda p: p.name)
def test_every_documented_command_runs(page, tmp_path, monkeypatch):
    (tmp_path / "examples").symlink_to(REPO / "examples")
    monkeypatch.chdir(tmp_path)
    for args in commands(page):
        if args[0] == "python":
            done = subprocess.run([sys.executable, *args[1:]], capture_output=True, text=True,
                                  timeout=120)
            assert done.returncode == 0, f"{' '.join(args)}\n{done.stderr}"
            continue
        res = CliRunner().invoke(main, [*args, "--quiet"] if args[0] != "demo" else
                                 [*args, "--upsample", "2", "--quiet"])
        assert res.exit_code == 0, f"holoradar {' '.join(args)}\n{res.output}"
    left = [f for _, _, files in os.walk(tmp_path) for f in files if f.endswith(".tmp")]
    assert not left  # no temporary file left behind anywhere (the examples link not followed)


@pytest.mark.slow
def test_all_pages_run_in_order_in_one_folder(tmp_path, monkeypatch):
    """A new user follows the README, then every page in turn, in one folder: no page's
    command meets a file an earlier page left (an output refused as existing) or needs
    one another page made. (Each page on its own: the test above.)"""
    (tmp_path / "examples").symlink_to(REPO / "examples")
    monkeypatch.chdir(tmp_path)
    for page in PAGES:
        for args in commands(page):
            if args[0] == "python":
                done = subprocess.run([sys.executable, *args[1:]], capture_output=True,
                                      text=True, timeout=120)
                assert done.returncode == 0, f"{page.name}: {' '.join(args)}\n{done.stderr}"
                continue
            res = CliRunner().invoke(main, [*args, "--quiet"] if args[0] != "demo" else
                                     [*args, "--upsample", "2", "--quiet"])
            assert res.exit_code == 0, f"{page.name}: holoradar {' '.join(args)}\n{res.output}"
