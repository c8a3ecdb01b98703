"""The README's commands work as typed: every `treeanim …` line parses, and the quick ones run
(with `.venv/bin` on PATH, as the README says) in a fresh folder."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from treeanim import cli

ROOT = Path(__file__).resolve().parents[1]


def readme_commands() -> list[str]:
    """Every command line of the README's ```sh blocks, continuation lines joined."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    lines = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        for line in block.replace("\\\n", " ").splitlines():
            line = line.split("  #")[0].strip()
            if line:
                lines.append(line)
    return lines


COMMANDS = readme_commands()
TREEANIM = [c for c in COMMANDS if c.startswith("treeanim ")]
#: Those quick enough to run in the suite (the rest render or bake minutes of video).
QUICK = [c for c in TREEANIM if "trace beam" in c or "export small_cherry" in c
         or ("render small_cherry" in c and "--seconds 3" in c)]


def test_the_readme_has_its_two_setup_commands_first():
    assert COMMANDS[:2] == ["scripts/view", "scripts/test"]
    assert len(TREEANIM) >= 10 and len(QUICK) >= 4


@pytest.mark.parametrize("command", TREEANIM)
def test_every_readme_command_parses(command):
    args = cli.build_parser().parse_args(shlex.split(command)[1:])
    assert args.command in ("render", "trace", "export", "view", "info", "bench", "list")


@pytest.mark.parametrize("command", QUICK)
def test_the_quick_readme_commands_run_as_typed(tmp_path, command):
    (tmp_path / "docs").mkdir()
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}")
    res = subprocess.run(command, shell=True, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    assert res.stdout.startswith("wrote "), res.stdout
