"""Every script in examples/ runs as its docstring says, and without matplotlib says what to
install in one line instead of a traceback."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

RUNS = {
    "lissajous.py": (["--seconds", "4"], ["fig4a.png", "fig4b.png", "fig4.png"]),
    "wind_spectrum.py": (["--seconds", "60"], ["wind_spectrum.png", "wind_slice.png"]),
    "batch_render.py": (["--size", "64x48"], None),
}


def test_every_example_is_covered():
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == sorted(RUNS)


@pytest.mark.parametrize("name", sorted(RUNS))
def test_example_runs(tmp_path, name):
    args, files = RUNS[name]
    res = subprocess.run([sys.executable, str(EXAMPLES / name), "--out", str(tmp_path / "out"), *args],
                         cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    made = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert made, "it wrote its pictures"
    if files:
        assert set(files) <= set(made), made
    if name == "batch_render.py":  # each still is named once, by treeanim render
        assert len(res.stdout.splitlines()) == len(made) == 2 * 5


@pytest.mark.parametrize("args,wind", [([], "the physical wind"), (["--paper", "--grid", "16"], "the paper's field")])
def test_wind_spectrum_plots_the_default_wind_or_the_papers(tmp_path, args, wind):
    """Issue 31: it plotted the paper's field only, not the physical wind every command uses."""
    res = subprocess.run([sys.executable, str(EXAMPLES / "wind_spectrum.py"), "--out", "out", "--seconds", "30",
                          *args], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    assert res.stdout.strip() == "wrote out/wind_spectrum.png and out/wind_slice.png (" + wind + ")"


@pytest.mark.parametrize("name", ["lissajous.py", "wind_spectrum.py"])
def test_example_without_matplotlib_says_what_to_install(tmp_path, name):
    code = ("import runpy, sys; sys.modules['matplotlib'] = None; "
            f"sys.argv = [{str(EXAMPLES / name)!r}, '--out', 'out']; "
            f"runpy.run_path({str(EXAMPLES / name)!r}, run_name='__main__')")
    res = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert res.returncode == 1
    assert "Traceback" not in res.stderr
    assert res.stderr.strip().splitlines() == [f"{name} needs matplotlib: .venv/bin/pip install -e '.[plots]' "
                                               "(from the repository)"]
