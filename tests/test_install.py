"""A plain (non-editable) wheel install holds every subpackage and finds its presets and shaders."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_installed_wheel_finds_assets(tmp_path):
    # Build from a clean copy: a build/ folder left in the checkout would leak stale files.
    src = tmp_path / "src"
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(".git", ".venv", "build", "dist", "*.egg-info", "__pycache__",
                                                             ".pytest_cache", ".hypothesis", "out", "docs"))
    wheels = tmp_path / "wheels"
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q", "-w", str(wheels), str(src)],
        check=True, capture_output=True, timeout=300,
    )
    (wheel,) = wheels.glob("treeanim-*.whl")
    site = tmp_path / "site"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(site), str(wheel)],
        check=True, capture_output=True, timeout=300,
    )
    shaders = sorted(p.name for p in (ROOT / "shaders").iterdir() if p.suffix in (".vert", ".frag", ".glsl"))
    code = (
        "import importlib.resources as r, json, treeanim as ta\n"
        "t = ta.load_preset('small_cherry')\n"
        "names = sorted(p.name for p in r.files('treeanim.shaders').iterdir() if p.name.split('.')[-1] in ('vert', 'frag', 'glsl'))\n"
        "print(json.dumps({'file': ta.__file__, 'presets': ta.list_presets(), 'leaves': t.stats()['leaves'], 'shaders': names}))\n"
    )
    env = dict(os.environ, PYTHONPATH=str(site))
    res = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    import json

    out = json.loads(res.stdout)
    assert out["file"].startswith(str(site)), "the installed copy was imported, not the source tree"
    assert set(out["presets"]) == {"beam", "small_cherry", "large_cherry", "tulip_poplar", "grassland"}
    assert out["leaves"] == 816
    assert out["shaders"] == shaders
    source = ROOT / "src" / "treeanim"
    packages = sorted(str(p.parent.relative_to(source)) for p in source.rglob("__init__.py"))
    installed = site / "treeanim"
    assert sorted(str(p.parent.relative_to(installed)) for p in installed.rglob("__init__.py")
                  if p.parent.name not in ("shaders", "presets")) == packages, "a subpackage is missing from the wheel"


def test_scripts_view_runs_as_typed_from_another_folder_without_reinstalling(tmp_path):
    """The README's first command, with an installed .venv: it does not reinstall (no pip run:
    scripts/view says "Installing" before it runs pip) and runs treeanim in the caller's folder,
    where a command's output lands."""
    res = subprocess.run([str(ROOT / "scripts" / "view"), "render", "beam", "--seconds", "0.1", "--size", "32x24",
                          "--out", "still.png", "--quiet"], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "still.png").is_file(), "the output lands in the caller's folder"
    assert "Installing" not in res.stdout + res.stderr
