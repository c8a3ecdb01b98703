"""Offline output (issue #6): `treeanim render` videos, frames and stills read back, Ctrl-C
keeping a playable file, `treeanim trace --paper` carrying the beam's modal frequencies (and a
trace of the tree model, pulled or dragged), `treeanim bench` reporting every preset, and bad
input refused with one line and no file.

Everything renders for real through EGL (Mesa llvmpipe in CI), at small sizes.
"""

from __future__ import annotations

import json
import math
import os
import re
import signal
import subprocess
import sys
import threading
import time

import imageio.v3 as iio
import imageio_ffmpeg
import numpy as np
import pytest

import treeanim as ta
from treeanim import cli
from treeanim.errors import InputError
from treeanim.offline import bench
from treeanim.offline.trace import run_trace, zero_crossing_frequency
from treeanim.render.camera import framed_camera
from treeanim.table1 import ROWS


def treeanim(*args, cwd=None, timeout=300):
    return subprocess.run([sys.executable, "-m", "treeanim", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=timeout)


def read_video(path):
    """(frames (K, H, W, 3) uint8, (W, H)) of an MP4 or GIF, decoded by ffmpeg."""
    gen = imageio_ffmpeg.read_frames(str(path))
    meta = next(gen)
    w, h = meta["size"]
    frames = [np.frombuffer(f, np.uint8).reshape(h, w, 3) for f in gen]
    return np.stack(frames), (w, h)


def moving_pixels(a, b, thr=30):
    """Pixels whose colour changed noticeably between two images."""
    return int((np.abs(a.astype(int) - b.astype(int)).max(axis=2) > thr).sum())


def leftovers(folder):
    """Hidden temporary files left in ``folder``."""
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


class RenderProgress:
    """A ``treeanim render`` running as ``proc`` (without --quiet), its stderr read as it runs
    (by a thread): tqdm's progress bar there counts the frames written to the output."""

    def __init__(self, proc):
        self.proc = proc
        self._chunks: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        for chunk in iter(lambda: self.proc.stderr.read(1), ""):
            self._chunks.append(chunk)

    def frames(self) -> int:
        """Frames written so far, as the progress bar last said."""
        counts = re.findall(r"\| *(\d+)/\d+ \[", "".join(self._chunks))
        return int(counts[-1]) if counts else 0

    def wait_for_frames(self, n: int = 1, timeout: float = 120.0) -> None:
        """Wait until ``n`` frames are written. This polls, with a timeout, as it waits on
        another process; the timeout is how long to wait before failing, never something
        measured."""
        end = time.monotonic() + timeout
        while self.frames() < n:
            if self.proc.poll() is not None or time.monotonic() > end:
                raise AssertionError(f"the render {'ended' if self.proc.poll() is not None else 'hung'} before "
                                     f"writing {n} frame(s): {''.join(self._chunks)[-500:]}")
            time.sleep(0.05)  # (the poll's interval)

    def stderr(self, timeout: float) -> str:
        """Everything the render wrote on stderr, once it has ended."""
        self.proc.wait(timeout)
        self._reader.join(timeout)
        return "".join(self._chunks)


# ------------------------------------------------------------------------------ render
@pytest.mark.parametrize("size", [(160, 120), (161, 121)], ids=["even", "odd"])
def test_render_mp4_reads_back_and_moves(tmp_path, size):
    w, h = size
    res = treeanim("render", "small_cherry", "--seconds", 1, "--fps", 10, "--size", f"{w}x{h}", "--wind", 12,
                   "--out", "clip.mp4", "--quiet", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "clip.mp4" in res.stdout and "10 frames" in res.stdout
    frames, vsize = read_video(tmp_path / "clip.mp4")
    assert vsize == (w + w % 2, h + h % 2), "odd sizes are padded up to even for H.264 / yuv420p"
    assert len(frames) == 10
    # The wind moves the tree: later frames differ from the first, and from each other.
    assert moving_pixels(frames[0], frames[-1]) > 0.01 * w * h
    assert moving_pixels(frames[5], frames[9]) > 0.003 * w * h
    # Not a blank clip: sky on top, a tree in the middle (dark, saturated pixels).
    mid = frames[-1][h // 4: 3 * h // 4, w // 3: 2 * w // 3].astype(int)
    assert mid.std() > 15
    if w % 2:  # the padding repeats the last column / row
        last = frames[-1].astype(int)
        assert np.abs(last[:, -1] - last[:, -2]).mean() < 12
    assert leftovers(tmp_path) == []


def test_render_gif(tmp_path):
    res = treeanim("render", "beam", "--seconds", 1, "--fps", 10, "--size", "96x72", "--pull", "0:600,0,400@0-0.3",
                   "--out", "beam.gif", "--quiet", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    frames = iio.imread(tmp_path / "beam.gif", index=None)
    assert frames.shape[:3] == (10, 72, 96)
    assert moving_pixels(frames[2], frames[6]) > 20  # the released beam swings
    assert leftovers(tmp_path) == []


def test_png_frames_and_still_match_the_simulated_times(tmp_path):
    w, h = 161, 121
    common = ["--size", f"{w}x{h}", "--wind", 12, "--quiet", "--seed", 3]
    res = treeanim("render", "small_cherry", "--seconds", 1.1, "--fps", 10, *common, "--out", "frames/", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    names = sorted(os.listdir(tmp_path / "frames"))
    assert names == [f"frame_{k:05d}.png" for k in range(11)]
    imgs = [iio.imread(tmp_path / "frames" / n) for n in names]
    assert all(im.shape == (h, w, 3) and im.dtype == np.uint8 for im in imgs), "PNG frames keep the exact size"
    assert moving_pixels(imgs[0], imgs[10]) > 0.01 * w * h
    assert moving_pixels(imgs[4], imgs[6]) > 0

    # A still at --seconds 1 is the state after 1 s of simulation: frame 10 of the clip above.
    res = treeanim("render", "small_cherry", "--seconds", 1, *common, "--out", "still.png", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    still = iio.imread(tmp_path / "still.png")
    assert still.shape == (h, w, 3)
    assert moving_pixels(still, imgs[10]) < 0.1 * moving_pixels(still, imgs[0])
    assert np.abs(still.astype(int) - imgs[10].astype(int)).mean() < 1.5
    assert leftovers(tmp_path) == [] and leftovers(tmp_path / "frames") == []


def test_the_default_camera_frames_the_tree(tmp_path):
    """Every preset fills the picture without being cut: tree pixels reach near the top (a
    tree) or near both sides (the wide, flat meadow) but the borders stay background (sky and
    ground)."""
    from treeanim.render.offscreen import OffscreenRenderer

    w, h = 128, 96
    with OffscreenRenderer(w, h, samples=0) as off:
        for name in ("small_cherry", "tulip_poplar", "beam", "grassland"):
            tree = ta.load_preset(name)
            off.load(tree)
            cam = framed_camera(tree, w, h)
            rest = tree.rest_positions, np.broadcast_to(np.eye(3), (tree.n_nodes, 3, 3))
            off.update(*rest)
            img = off.render(cam)
            off.update(*rest, present=np.zeros(tree.n_objects, bool))
            bg = off.render(cam)
            mask = np.abs(img.astype(int) - bg.astype(int)).max(axis=2) > 8  # grass is close to the ground
            rows, cols = np.nonzero(mask)
            fills = rows.min() < 0.15 * h or (cols.min() < 0.15 * w and cols.max() > 0.85 * w)
            assert fills, (name, rows.min(), cols.min(), cols.max())  # up to the top, or across
            assert not (mask[0].any() or mask[:, 0].any() or mask[:, -1].any()), name  # (shadows reach the bottom)


def test_ctrl_c_keeps_a_playable_video(tmp_path):
    """SIGINT to the whole process group (what Ctrl-C in a terminal does, ffmpeg included)."""
    proc = subprocess.Popen([sys.executable, "-m", "treeanim", "render", "small_cherry", "--seconds", "60", "--fps", "10",
                             "--size", "96x72", "--out", "long.mp4"], cwd=tmp_path,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        progress = RenderProgress(proc)
        progress.wait_for_frames(3)
        assert leftovers(tmp_path), "the video is written beside its name until it is finished"
        assert not (tmp_path / "long.mp4").exists()
        os.killpg(proc.pid, signal.SIGINT)
        err = progress.stderr(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    frames, size = read_video(tmp_path / "long.mp4")
    assert size == (96, 72) and 1 <= len(frames) < 600
    assert f"kept {len(frames)} frames of 600" in err
    assert leftovers(tmp_path) == []


# ------------------------------------------------------------------------------ trace
def test_trace_after_release_has_the_beams_modal_frequencies(tmp_path):
    """The paper's model (--paper): the beam swings at its own modes."""
    tree = ta.load_preset("beam")
    rest_tip = tree.rest_positions[tree.object_nodes(0)[-1]]
    # A diagonal pull bending the tip by ~8 % of the beam's length (the linear range), sized
    # from the preset's own stiffness by a small probe pull.
    probe = ta.Simulation(tree, model="paper")
    probe.pull(0, (1.0, 0.0, 0.8))
    probe.step(30.0)  # a held pull settles (critically damped): one long step reaches it
    length = np.linalg.norm(np.diff(tree.rest_positions[tree.object_nodes(0)], axis=0), axis=1).sum()
    force = np.array([1.0, 0.0, 0.8]) * 0.08 * length / np.linalg.norm(probe.tip_position(0) - rest_tip)
    res = treeanim("trace", "beam", "--paper", "--pull", ",".join(f"{v:.6g}" for v in force), "--seconds", 8,
                   "--out", "trace.csv", "--plot", "trace.png", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    with open(tmp_path / "trace.csv") as fh:
        assert fh.readline().strip() == "t,x,y,z"
    data = np.loadtxt(tmp_path / "trace.csv", delimiter=",", skiprows=1)
    t, tip = data[:, 0], data[:, 1:]
    assert t[0] == 0 and np.allclose(np.diff(t), 1 / 240, atol=2e-6) and t[-1] == pytest.approx(8, abs=1e-3)

    sim = ta.Simulation(tree, model="paper")
    f, zeta = sim.modes.f[0], sim.modes.zeta[0]  # columns u, v, w
    d = tip - rest_tip
    assert 0.04 * length < np.hypot(d[0, 0], d[0, 2]) < 0.15 * length, "released from the pull's static deflection"
    # Free swing: a load along u (x here) swings at f_w, one along w (z) at f_u (docs/design.md §5),
    # each at the damped frequency f·sqrt(1 - ζ²).
    fx = zero_crossing_frequency(t, d[:, 0])
    fz = zero_crossing_frequency(t, d[:, 2])
    assert fx == pytest.approx(f[2] * math.sqrt(1 - zeta[2] ** 2), rel=0.01)
    assert fz == pytest.approx(f[0] * math.sqrt(1 - zeta[0] ** 2), rel=0.01)
    # The spectrum peaks there too (zero-padded FFT of the x swing).
    spec = np.abs(np.fft.rfft(d[:, 0] - d[:, 0].mean(), 1 << 16))
    freq = np.fft.rfftfreq(1 << 16, t[1] - t[0])
    assert freq[np.argmax(spec)] == pytest.approx(f[2], rel=0.03)
    # Damping: successive x maxima shrink by exp(-2π ζ / sqrt(1 - ζ²)) per period.
    x = d[:, 0]
    peaks = np.flatnonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:]) & (x[1:-1] > 0)) + 1
    decrement = np.log(x[peaks[0]] / x[peaks[-1]]) / (len(peaks) - 1)
    assert decrement / (2 * np.pi) == pytest.approx(zeta[2], rel=0.2)
    png = iio.imread(tmp_path / "trace.png")
    assert png.shape[0] > 400 and png.shape[1] > 400 and png[..., :3].std() > 10
    assert f"{f[0]:.3f}" in res.stdout


#: The tree model's drag diverges at steps shorter than about 1/100 s (physics/treestep.py's
#: grab; found while porting the command line): the trace's default 240 Hz.


@pytest.mark.parametrize("held", [["--pull", "10,0,5"], ["--drag=-0.25,1.97,0.1", "--rate", "60"],
                                  ["--drag=-0.25,1.97,0.1"]],
                         ids=["pull", "drag", "drag-240Hz"])
def test_trace_of_the_tree_model_pulled_or_dragged(tmp_path, capsys, held):
    """The tree model (the default) traces a pull or a drag of the tip toward a world point; it
    has no per-object modes to print."""
    out = tmp_path / "t.csv"
    assert cli.main(["trace", "beam", *held, "--seconds", "2", "--out", str(out), "--plot", str(tmp_path / "t.png")]) == 0
    text = capsys.readouterr().out
    assert "modes f" not in text and "held deflection" in text and (tmp_path / "t.png").stat().st_size > 0
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    rest = ta.load_preset("beam").rest_positions[-1]
    assert np.all(np.isfinite(data))
    d0 = data[0, 1:] - rest
    if held[0].startswith("--drag"):  # released from near the target, 10 cm beside the tip
        assert d0[0] > 0.05 and d0[2] > 0.05
    assert np.linalg.norm(data[-1, 1:] - rest) < np.linalg.norm(d0), "it swings back towards rest"


def test_trace_with_fewer_than_two_samples_is_refused():
    from treeanim.physics.simulation import Simulation

    sim = Simulation(ta.load_preset("beam"))
    for seconds, rate in ((5.0, 0.01), (1e-9, 240.0)):
        with pytest.raises(InputError, match="needs at least 2 samples"):
            run_trace(sim, 0, (1.0, 0.0, 0.0), 0.5, seconds, rate)
    assert sim.time == 0.0 and not sim.pulls, "refused before anything was simulated"
    tr = run_trace(sim, 0, (1.0, 0.0, 0.0), 0.05, 1.0 / 240, 240.0)  # the shortest trace: 2 samples
    assert len(tr.times) == 2 and np.all(np.isfinite(tr.tips))


@pytest.mark.parametrize("hold,seconds,rate", [(0.5, 1e12, 1000.0), (1e12, 1.0, 1000.0)])
def test_a_trace_too_long_to_keep_is_refused_before_it_starts(hold, seconds, rate):
    """From Python (the command line's frame check aside) a trace of 10^15 samples tried to
    allocate them; a hold of 10^15 steps would never end."""
    from treeanim.physics.simulation import Simulation

    sim = Simulation(ta.load_preset("beam"))
    with pytest.raises(InputError, match="samples; at most"):
        run_trace(sim, 0, (1.0, 0.0, 0.0), hold, seconds, rate)
    assert sim.time == 0.0 and not sim.pulls


# ------------------------------------------------------------------------------ bench
def test_bench_wind_beyond_the_fields_limit_is_input_error(monkeypatch):
    from treeanim.physics.wind import MAX_SPEED

    def no_context(*a, **k):
        raise AssertionError("a GL context was made before the wind was checked")

    monkeypatch.setattr(bench, "offscreen", no_context)
    for wind in (2 * MAX_SPEED, -1.0, float("nan")):
        with pytest.raises(InputError, match="--wind"):
            bench.run_bench(["beam"], 16, 16, frames=1, steps=1, samples=0, wind=wind, quiet=True)
def test_bench_json_reports_every_preset(tmp_path):
    res = treeanim("bench", "--size", "64x36", "--frames", 2, "--steps", 5, "--json", "bench.json", "--quiet",
                   cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    doc = json.loads((tmp_path / "bench.json").read_text())
    assert [r["key"] for r in doc["rows"]] == list(ROWS)
    assert doc["gl_renderer"] and doc["machine"]["cpu"] and doc["machine"]["cores"] >= 1
    assert doc["size"] == [64, 36]
    for r in doc["rows"]:
        for k in ("sim_ms", "render_ms", "sim_ms_min", "render_ms_min", "fps"):
            assert math.isfinite(r[k]) and r[k] > 0, (r["key"], k)
        assert r["sim_ms_min"] <= r["sim_ms"] <= r["sim_ms_p90"], r["key"]
        assert r["render_ms_min"] <= r["render_ms"] <= r["render_ms_p90"], r["key"]
        # The counts reported are those of the tree measured: the preset's own statistics.
        preset, season = ROWS[r["key"]]
        stats = ta.load_preset(preset).stats(season)
        assert (r["objects"], r["nodes"], r["triangles"]) == (stats["objects"], stats["nodes"], stats["triangles"])
        assert abs(r["nodes"] / r["paper_nodes"] - 1) < 0.1
    winter = doc["rows"][2]
    assert winter["key"] == "large_cherry@winter" and winter["triangles"] < doc["rows"][1]["triangles"] / 5
    assert "| large_cherry (winter) |" in res.stdout and doc["gl_renderer"] in res.stdout


def test_ctrl_c_in_bench_keeps_the_finished_rows_printed_and_in_the_json(tmp_path, monkeypatch, capsys):
    """Issue 31: a Ctrl-C threw away every finished row (the table and the JSON came only at the
    end). Ctrl-C, raised while the second preset steps: the first row was already printed when
    it came, it is in the JSON with ``interrupted``, and the exit status is 130."""
    real = bench.bench_row
    seen = {}

    def row(key, *a, progress=None, **kw):
        if key != "small_cherry":
            return real(key, *a, progress=progress, **kw)

        def ctrl_c():
            seen["stdout"] = capsys.readouterr().out  # what was printed before the interruption
            raise KeyboardInterrupt

        return real(key, *a, progress=ctrl_c, **kw)

    monkeypatch.setattr(bench, "bench_row", row)
    out = tmp_path / "bench.json"
    code = cli.main(["bench", "--presets", "beam", "small_cherry", "--size", "32x24", "--frames", "1", "--steps", "2",
                     "--quiet", "--json", str(out)])
    rest = capsys.readouterr()
    assert code == 130
    assert "| beam | 1 / — |" in seen["stdout"] and "| preset |" in seen["stdout"]  # printed as it finished
    assert "small_cherry" not in seen["stdout"] + rest.out
    doc = json.loads(out.read_text())
    assert doc["interrupted"] is True and [r["key"] for r in doc["rows"]] == ["beam"]
    assert doc["rows"][0]["sim_ms"] > 0 and doc["gl_renderer"]
    assert rest.out.strip() == f"wrote {out} (1 of 2 rows)"
    assert rest.err.strip() == "interrupted: 1 of 2 rows measured"


def test_ctrl_c_in_bench_before_any_row_writes_nothing(tmp_path, monkeypatch, capsys):
    def interrupted(*a, **kw):
        raise KeyboardInterrupt

    monkeypatch.setattr(bench, "bench_row", interrupted)
    out = tmp_path / "bench.json"
    code = cli.main(["bench", "--presets", "beam", "--size", "32x24", "--quiet", "--json", str(out)])
    assert code == 130 and not out.exists() and os.listdir(tmp_path) == []
    assert capsys.readouterr().err.strip() == f"interrupted: 0 of 1 row measured; nothing written to {out}"


# ------------------------------------------------------------------------------ bad input
BAD = [
    (["render", "small_cherry", "--out", "clip.avi"], "unknown extension"),
    (["render", "small_cherry", "--out", "/nonexistent/dir/clip.mp4"], "does not exist"),
    (["render", "small_cherry", "--out", "/proc/clip.mp4"], "cannot create files"),
    (["render", "small_cherry", "--out", "notes.txt/clip.mp4"], "does not exist"),
    (["render", "small_cherry", "--out", "notes.txt/"], "not a folder"),
    (["render", "small_cherry", "--out", "c.mp4", "--pull", "99999:1,0,0@0-1"], "objects 0 to 875"),
    (["render", "small_cherry", "--out", "c.mp4", "--seconds", "0"], "positive"),
    (["render", "small_cherry", "--out", "c.png", "--seconds=-2"], "positive"),
    (["render", "small_cherry", "--out", "c.mp4", "--fps", "0"], "positive"),
    (["render", "small_cherry", "--out", "c.mp4", "--seconds", "0.01", "--fps", "10"], "gives no frame"),
    (["render", "small_cherry", "--out", "c.mp4", "--size", "0x120"], "at least 1"),
    (["render", "small_cherry", "--out", "c.mp4", "--size=-160x120"], "WIDTHxHEIGHT"),
    (["render", "small_cherry", "--out", "c.mp4", "--size", "160"], "WIDTHxHEIGHT"),
    (["render", "small_cherry", "--out", "c.mp4", "--size", "160x120x3"], "WIDTHxHEIGHT"),
    (["render", "small_cherry", "--out", "c.mp4", "--distance", "0"], "in [0.01, 100000]"),
    (["render", "beam", "--out", "c.png", "--distance", "1e-320"], "in [0.01, 100000]"),  # was an empty sky
    (["render", "oak", "--out", "c.mp4"], "unknown preset"),
    (["trace", "beam", "--object", "1", "--pull", "1,0,0", "--out", "t.csv"], "objects 0 to 0"),
    (["trace", "beam", "--object", "-1", "--pull", "1,0,0", "--out", "t.csv"], "objects 0 to 0"),
    (["trace", "beam", "--pull", "1,0", "--out", "t.csv"], "three finite numbers"),
    (["trace", "beam", "--pull", "1,0,0", "--out", "t.txt"], "unknown extension"),
    (["trace", "beam", "--pull", "1,0,0", "--out", "t.csv", "--seconds", "0"], "positive"),
    (["trace", "beam", "--pull", "1,0,0", "--out", "t.csv", "--plot", "/proc/t.png"], "cannot create files"),
    (["bench", "--presets", "oak"], "unknown"),
    (["bench", "--json", "b.txt"], "unknown extension"),
    (["bench", "--size", "1280x"], "WIDTHxHEIGHT"),
    (["bench", "--frames", "0"], "positive"),
    (["render", "beam", "--pull", "0:2e9,0,0@0-1", "--out", "x.png"], "at most 1e+09 N"),
    (["export", "beam", "--pull", "0:0,-2e9,0@0-1", "--out", "x.glb"], "at most 1e+09 N"),
    (["trace", "beam", "--pull", "0,0,2e9", "--out", "t.csv"], "at most 1e+09 N"),
    (["render", "beam", "--samples", "3", "--out", "x.png"], "one of 0, 1, 2, 4, 8, 16"),
    (["render", "beam", "--seconds", "1e6", "--fps", "0.01", "--out", "x.mp4"], "simulation steps; at most"),
    (["export", "beam", "--seconds", "4e4", "--fps", "1", "--out", "x.glb"], "at most 2,000,000"),
    (["view", "beam", "--samples", "3"], "one of 0, 1, 2, 4, 8, 16"),
    (["render", "beam", "--out", "a" * 300 + ".png"], "bytes long"),
    (["render", "beam", "--fps", "9" * 5000, "--out", "x.png"], "(5,000 characters)"),  # not echoed whole
    (["render", "beam", "--out", "no/such/a\nb.png"], "a\\nb.png"),  # a newline in a path: still one line
    (["export", "beam", "--out", "b" * 300 + ".glb"], "bytes long"),
    # a trailing '/' names a folder: export wrote x.gltf (these commands write one file; only
    # render takes a folder, for its frames)
    (["export", "beam", "--out", "x.gltf/"], "x.gltf/: ends in '/', a folder's name; name a file (e.g. x.gltf)"),
    (["trace", "beam", "--pull", "1,0,0", "--out", "t.csv/"], "ends in '/'"),
    (["bench", "--presets", "beam", "--json", "b.json/"], "--json b.json/: ends in '/'"),
]


@pytest.mark.parametrize("args,words", BAD, ids=[" ".join(a[:1] + a[2:] if a[0] != "bench" else a) for a, _ in BAD])
def test_bad_input_one_line_exit_2_no_file(tmp_path, monkeypatch, capsys, args, words):
    (tmp_path / "notes.txt").write_text("a file, not a folder\n")
    monkeypatch.chdir(tmp_path)
    try:
        code = cli.main(args)
    except SystemExit as e:  # argparse
        code = e.code
    out, err = capsys.readouterr()
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert words in lines[0] and "Traceback" not in err
    assert sorted(os.listdir(tmp_path)) == ["notes.txt"], "no file is left behind"


@pytest.mark.parametrize("args", [["export", "beam", "--out", "{d}.glb"],  # (render takes a folder: its frames)
                                  ["trace", "beam", "--pull", "1,0,0", "--out", "{d}.csv"],
                                  ["bench", "--presets", "beam", "--json", "{d}.json"]])
def test_an_output_that_is_a_folder_is_refused_before_the_job(tmp_path, monkeypatch, capsys, args):
    from treeanim.render.offscreen import OffscreenRenderer

    monkeypatch.chdir(tmp_path)
    for suffix in (".glb", ".csv", ".json"):
        (tmp_path / f"out{suffix}").mkdir()
    args = [a.format(d="out") for a in args]
    started = []  # refused up front: no simulation is set up, nothing is rendered
    for cls in (ta.Simulation, OffscreenRenderer):
        monkeypatch.setattr(cls, "__init__", lambda self, *a, cls=cls, **kw: started.append(cls.__name__))
    code = cli.main(args)
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "is a folder" in err, err
    assert started == []


def test_a_still_after_the_tiniest_time_is_the_rest_pose(tmp_path, capsys):
    out = tmp_path / "still.png"
    assert cli.main(["render", "beam", "--seconds", "5e-324", "--size", "32x24", "--out", str(out), "--quiet"]) == 0
    assert out.stat().st_size > 0


def test_standard_output_on_a_full_disk_is_one_line_and_exit_1():
    with open("/dev/full", "w") as full:
        res = subprocess.run([sys.executable, "-m", "treeanim", "list"], stdout=full, stderr=subprocess.PIPE,
                             text=True, timeout=120)
    assert res.returncode == 1
    assert res.stderr.strip().splitlines() == ["treeanim: error: No space left on device"], res.stderr


def test_an_ascii_terminal_or_a_closed_standard_output_is_no_traceback():
    """Issue 31: with PYTHONIOENCODING=ascii `info` raised UnicodeEncodeError after its work
    (its table has en dashes); `treeanim list >&-` raised AttributeError."""
    env = dict(os.environ, PYTHONIOENCODING="ascii")
    res = subprocess.run([sys.executable, "-m", "treeanim", "info", "beam"], capture_output=True, text=True,
                         env=env, timeout=120)
    assert res.returncode == 0 and "Traceback" not in res.stderr, res.stderr
    assert "\\u2013" in res.stdout  # the en dash, escaped
    res = subprocess.run([sys.executable, "-m", "treeanim", "list"], stderr=subprocess.PIPE, text=True,
                         preexec_fn=lambda: os.close(1), timeout=120)
    assert res.returncode == 0 and res.stderr == "", res.stderr


def test_ctrl_c_while_the_command_line_starts_is_a_quiet_exit_130(monkeypatch, capsys):
    def interrupted():
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "build_parser", interrupted)
    assert cli.main(["list"]) == 130
    assert capsys.readouterr().err.strip() == "treeanim: interrupted"


@pytest.mark.parametrize("out", ["clip.mp4", "still.png", "tree.glb"])
def test_a_write_that_fails_part_way_keeps_the_old_file_and_says_so(tmp_path, out):
    """A full disk, played by a file-size limit on the command and its ffmpeg (EFBIG on the
    first write past 20 kB): exit 1, one line naming the file, the previous file untouched and
    no temporary file left."""
    import resource

    target = tmp_path / out
    old = b"the previous file" * 100
    target.write_bytes(old)
    cmd = "export" if out.endswith(".glb") else "render"
    extra = ["--seconds", "2", "--size", "320x240", "--quiet"] if cmd == "render" else ["--seconds", "1", "--quiet"]

    def limited():
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))

    res = subprocess.run([sys.executable, "-m", "treeanim", cmd, "small_cherry", "--out", str(target), *extra],
                         preexec_fn=limited, capture_output=True, text=True, timeout=300)
    assert res.returncode == 1, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"treeanim: error: {target}") and "Traceback" not in res.stderr
    assert "wrote" not in res.stdout
    assert target.read_bytes() == old
    assert sorted(p.name for p in tmp_path.iterdir()) == [out]


FFMPEG_SAYS = ("[out#0/mp4 @ 0x55d0c0a1b2c0] Error writing trailer: No space left on device",
               "[out#0/mp4 @ 0x55d0c0a1b2c0] Error closing file: No space left on device")


@pytest.mark.parametrize("when", ["at the end", "at once"])
def test_a_failing_encoder_is_our_one_line_not_ffmpegs(tmp_path, monkeypatch, capfd, when):
    """Issue 31: on a full disk ffmpeg's own two lines came before ours. An ffmpeg that says
    those two lines and exits 1, after reading every frame (the trailer did not fit) or at
    once (the pipe breaks under our writes): standard error is our one line, with its reason;
    the previous file is kept and no temporary file is left. (A real full tmpfs gives the same
    line: 'the video encoder failed (Error writing trailer: No space left on device)'.)"""
    fake = tmp_path / "ffmpeg"
    drain = "cat > /dev/null\n" if when == "at the end" else ""
    fake.write_text("#!/bin/sh\n" + drain + "".join(f"echo '{line}' >&2\n" for line in FFMPEG_SAYS) + "exit 1\n")
    fake.chmod(0o755)
    monkeypatch.setenv("IMAGEIO_FFMPEG_EXE", str(fake))
    out = tmp_path / "clip.mp4"
    out.write_bytes(b"the previous video")
    code = cli.main(["render", "beam", "--seconds", "0.5", "--fps", "30", "--size", "64x48", "--quiet",
                     "--out", str(out)])
    captured = capfd.readouterr()
    assert code == 1
    assert captured.err.splitlines() == [
        f"treeanim: error: {out}: the video encoder failed (Error writing trailer: No space left on device); "
        "any previous file is kept"], captured.err
    assert out.read_bytes() == b"the previous video"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["clip.mp4", "ffmpeg"]


def test_sigterm_during_a_render_leaves_no_temporary_file(tmp_path):
    out = tmp_path / "clip.mp4"
    proc = subprocess.Popen([sys.executable, "-m", "treeanim", "render", "small_cherry", "--out", str(out),
                             "--seconds", "20", "--size", "320x240"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        progress = RenderProgress(proc)
        progress.wait_for_frames(3)  # a few frames into the video
        proc.send_signal(signal.SIGTERM)
        err = progress.stderr(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 143, err
    assert "Traceback" not in err
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")], "no hidden .part file is left"


def test_a_trace_too_short_for_zero_crossings_says_so(tmp_path, capsys):
    assert cli.main(["trace", "beam", "--pull", "1,0,0", "--seconds", "0.05", "--out", str(tmp_path / "t.csv")]) == 0
    out = capsys.readouterr().out
    assert "too few to tell" in out and "nan" not in out


def test_bench_measures_a_scene_as_a_row(tmp_path):
    """`--presets` takes the shipped scenes too: the orchard's row counts all its trees."""
    res = treeanim("bench", "--presets", "orchard", "--size", "32x24", "--frames", 1, "--steps", 1, "--json", "b.json",
                   "--quiet", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    (row,) = json.loads((tmp_path / "b.json").read_text())["rows"]
    stats = ta.load_scene("orchard").stats(0.0)
    assert row["key"] == "orchard" and row["paper_objects"] is None
    assert (row["objects"], row["nodes"], row["triangles"]) == (stats["objects"], stats["nodes"], stats["triangles"])
    assert math.isfinite(row["fps"]) and row["fps"] > 0
