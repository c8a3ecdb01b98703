"""A plain (non-editable) wheel install holds every subpackage and finds its presets, scenes and
shaders."""

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
        "plants = sorted(p.name for p in (r.files('treeanim.presets') / 'scenes' / 'plants').iterdir())\n"
        "print(json.dumps({'file': ta.__file__, 'presets': ta.list_presets(), 'leaves': t.stats()['leaves'], 'shaders': names,\n"
        "                  'scenes': ta.list_scenes(), 'plants': plants}))\n"
    )
    env = dict(os.environ, PYTHONPATH=str(site))
    res = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    import json

    out = json.loads(res.stdout)
    assert out["file"].startswith(str(site)), "the installed copy was imported, not the source tree"
    assert set(out["presets"]) == {"beam", "small_cherry", "large_cherry", "tulip_poplar", "grassland"}
    assert out["leaves"] == 816
    assert out["scenes"] == ["orchard", "woodland"]
    assert out["plants"] == ["meadow.toml", "sapling.toml", "shrub.toml"]
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


# ---------------------------------------------------------------------------- the first install
QUIET_EDITABLE = "ignore:Editable installation:UserWarning"


def _fake(path: Path, body: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("#!/bin/sh\n" + body)
    path.chmod(0o755)


def _fake_checkout(tmp_path: Path) -> tuple[Path, Path, dict]:
    """A copy of scripts/ and pyproject.toml whose tools are fakes that log how they were run:
    .venv/bin/python (pip and pytest; 'import treeanim' fails until pip ran), npm, dpkg-query
    and python3 (every Debian package there: nothing is installed for real)."""
    repo, log = tmp_path / "repo", tmp_path / "log"
    shutil.copytree(ROOT / "scripts", repo / "scripts")
    shutil.copy(ROOT / "pyproject.toml", repo)
    _fake(repo / ".venv" / "bin" / "python",
          f'echo "python PYTHONWARNINGS=$PYTHONWARNINGS $*" >> {log}\n'
          f'if [ "$1" = "-c" ] && [ ! -e {tmp_path}/installed ]; then exit 1; fi\n'
          f'if [ "$2" = "pip" ] && [ "$3" = "install" ] && [ "$5" = "-e" ]; then touch {tmp_path}/installed; fi\n')
    _fake(repo / ".venv" / "bin" / "treeanim", f'echo "treeanim $*" >> {log}\n')
    bin_ = tmp_path / "bin"
    _fake(bin_ / "npm", f'echo "npm $*" >> {log}\nmkdir -p "$6/node_modules/gltf-validator" "$6/node_modules/three"\n')
    _fake(bin_ / "dpkg-query", "printf 'install ok installed'\n")
    _fake(bin_ / "python3", "exit 0\n")  # (venv and ensurepip are there: no apt-get)
    env = dict(os.environ, PATH=f"{bin_}{os.pathsep}{os.environ['PATH']}")
    env.pop("PYTHONWARNINGS", None)
    return repo, log, env


def test_scripts_test_says_what_it_installs_without_setuptools_box(tmp_path):
    """Issue 31: the first `scripts/test` ran npm for 74 s with no output, and its editable
    install printed setuptools' boxed note, which reads as an error. Each long install now says
    what it does first, pip runs with that note filtered out, and a second run installs nothing."""
    repo, log, env = _fake_checkout(tmp_path)
    res = subprocess.run([str(repo / "scripts" / "test"), "-q"], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    said = res.stdout.splitlines()
    assert len(said) == 2 and said[0].startswith("Installing treeanim (editable) and its test extras into .venv")
    assert said[1].startswith("Installing the Khronos glTF Validator and three.js into .venv/node with npm"), res.stdout
    runs = log.read_text().splitlines()
    assert f"python PYTHONWARNINGS={QUIET_EDITABLE} -m pip install -q -e .[test]" in runs
    assert any(r.startswith("npm install") for r in runs) and runs[-1] == "python PYTHONWARNINGS= -m pytest -q"
    log.unlink()
    res = subprocess.run([str(repo / "scripts" / "test")], cwd=tmp_path, env=env, capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0 and res.stdout == "", res.stdout
    assert log.read_text().splitlines() == ["python PYTHONWARNINGS= -m pytest"]


def test_scripts_view_installs_without_setuptools_box(tmp_path):
    repo, log, env = _fake_checkout(tmp_path)
    res = subprocess.run([str(repo / "scripts" / "view"), "list"], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert res.stdout.startswith("Installing treeanim into") and res.stderr == ""
    runs = log.read_text().splitlines()
    assert f"python PYTHONWARNINGS={QUIET_EDITABLE} -m pip install -q -e {repo}" in runs and runs[-1] == "treeanim list"


def test_the_filter_hides_setuptools_editable_note_and_nothing_else():
    """The scripts' filter against the real warning: setuptools' InformationOnly note, as its
    editable install emits it (pip shows what the build backend warns)."""
    code = ("from setuptools.warnings import InformationOnly, SetuptoolsWarning\n"
            "InformationOnly.emit('Editable installation.', 'Please be careful with folders ...')\n"
            "SetuptoolsWarning.emit('Something else.', 'still shown')\n")
    for script in ("test", "view"):
        assert QUIET_EDITABLE in (ROOT / "scripts" / script).read_text(), script
    shown = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                           env={k: v for k, v in os.environ.items() if k != "PYTHONWARNINGS"}).stderr
    assert "Editable installation" in shown and "Something else" in shown
    quiet = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                           env=dict(os.environ, PYTHONWARNINGS=QUIET_EDITABLE)).stderr
    assert "Editable installation" not in quiet and "Something else" in quiet, quiet
