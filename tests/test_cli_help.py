"""What the command line tells a new user (issue 31): `treeanim list` describes and sizes each
preset, `info --objects` gives the object numbers `--pull OBJECT:…` takes, `view --help` lists
the viewer's keys, and every command's help says it reads TreeQSM files."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import treeanim as ta
from treeanim import cli
from treeanim.app.keys import BINDINGS, MOUSE

ASSET = Path(__file__).resolve().parents[1] / "assets" / "qsm" / "synthetic_broadleaf.txt"


def run(capsys, *args) -> str:
    assert cli.main(list(args)) == 0
    return capsys.readouterr().out


def help_of(command: str) -> str:
    return " ".join(cli.build_parser()._subparsers._group_actions[0].choices[command].format_help().split())


def test_list_gives_each_presets_size_and_description(capsys):
    lines = run(capsys, "list").splitlines()
    assert [line.split()[0] for line in lines] == ta.list_presets() + ta.list_scenes()  # the scenes after
    lines = lines[:len(ta.list_presets())]
    for line in lines:
        name = line.split()[0]
        tree = ta.load_preset(name)
        stats = tree.stats(0.0)
        assert f"{stats['objects']:,} object" in line and f"{stats['triangles']:,} triangles" in line, line
        assert f"{tree.rest_positions[:, 1].max():.1f} m tall" in line, line
    cherry = next(line for line in lines if line.startswith("small_cherry"))
    assert "A young cherry (Prunus)" in cherry


def test_info_objects_lists_the_numbers_pull_takes(capsys):
    tree = ta.load_preset("small_cherry")
    lines = run(capsys, "info", "small_cherry", "--objects").splitlines()
    assert lines[0].split()[:2] == ["object", "kind"] and len(lines) == tree.n_objects + 1
    rows = [line.split() for line in lines[1:]]
    assert [int(r[0]) for r in rows] == list(range(tree.n_objects))
    assert [r[1] for r in rows] == list(tree.kind) and [int(r[3]) for r in rows] == list(tree.parent)
    for i in (0, int(np.flatnonzero(tree.kind == "leaf")[0]), tree.n_objects - 1):
        nodes = tree.rest_positions[tree.object_nodes(i)]
        length = np.linalg.norm(np.diff(nodes, axis=0), axis=1).sum()
        assert float(rows[i][5]) == pytest.approx(length, abs=6e-4)
        assert [float(v.rstrip(",")) for v in rows[i][7:10]] == pytest.approx(nodes[-1], abs=6e-3)
    # the plain table says where the numbers are
    assert f"numbered 0 to {tree.n_objects - 1}" in run(capsys, "info", "small_cherry").splitlines()[-1]


def test_info_objects_of_a_treeqsm_model(capsys):
    tree = ta.load_tree(ASSET)
    lines = run(capsys, "info", str(ASSET), "--objects").splitlines()
    assert len(lines) == tree.n_objects + 1 and lines[1].split()[1:4] == ["branch", "1", "-1"]


def test_help_names_treeqsm_files_object_numbers_and_the_viewers_keys():
    for command in ("info", "view", "render", "export", "trace"):
        text = help_of(command)
        assert "TreeQSM cylinder model" in text and ".mat" in text, command
    assert "--objects" in help_of("info")
    for command in ("render", "export"):
        assert "'treeanim info PRESET --objects' lists them" in help_of(command), command
    assert "'treeanim info PRESET --objects' lists them" in help_of("trace")
    view = help_of("view")
    for b in BINDINGS:
        assert f"{b.label} {b.does}" in view, b.label
    for what, does in MOUSE:
        assert f"{what}: {does}" in view, what


def test_the_command_line_loads_glfw_only_for_the_viewers_help():
    code = ("import sys\nfrom treeanim import cli\np = cli.build_parser()\np.parse_args(['list'])\n"
            "print('glfw' in sys.modules)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert res.stdout.strip() == "False", res.stderr
