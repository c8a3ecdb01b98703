"""``treeanim bench``: the paper's Table 1 measured on this machine: our counts beside the
paper's, median simulation and render times, and the frame rate they allow."""

from __future__ import annotations

import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..model.load import load_named
from ..render.camera import framed_camera
from ..table1 import ROWS, TABLE1, TABLE1_FPS
from ..validate import float_within
from .render import offscreen


def machine_info() -> dict:
    """CPU model, cores, OS and Python of this machine."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        load = [round(x, 2) for x in os.getloadavg()]
    except OSError:
        load = None
    return {"cpu": cpu, "cores": os.cpu_count(), "system": f"{platform.system()} {platform.release()}",
            "python": platform.python_version(), "numpy": np.__version__, "load_average": load}


def bench_row(key: str, off, width: int, height: int, frames: int, steps: int, wind: float = 5.0,
              progress=None) -> dict:
    """One row of the benchmark: our counts, the paper's, and the medians in milliseconds.

    The simulation is timed per 1/60 s frame as the viewer takes it (the frame driver's
    :meth:`~treeanim.driver.FrameDriver.advance` and the pose the renderer reads), over
    ``steps`` frames after 5 of warm-up; the render per frame over ``frames`` frames."""
    import treeanim as ta

    from ..driver import STEP, FrameDriver

    preset, season = ROWS.get(key, (key, 0.0))
    tree = load_named(preset)  # a preset or a scene
    stats = tree.stats(season)
    try:
        wind_field = ta.WindField(speed=wind, seed=0)
    except ValueError as e:
        raise InputError(f"--wind {wind:g}: {' '.join(str(e).split())}") from None
    sim = ta.Simulation(tree, wind=wind_field, season=season, seed=0)
    driver = FrameDriver()

    def frame() -> None:
        driver.advance(sim, STEP)
        sim.positions, sim.rotations  # the pose is built lazily

    for _ in range(5):
        frame()
    sim_ms = []
    for _ in range(steps):
        t0 = time.perf_counter()
        frame()
        sim_ms.append((time.perf_counter() - t0) * 1e3)
        if progress:
            progress()
    off.resize(width, height)
    off.load(tree)
    cam = framed_camera(tree, width, height, present=sim.present)
    ren_ms = []
    for k in range(frames + 2):
        frame()
        t0 = time.perf_counter()
        off.update(sim.positions, sim.rotations, sim.shown, wind=sim.wind, time=sim.time)
        off.render(cam, season=season)  # draws, resolves and reads the pixels back: the GPU is done
        if k >= 2:  # the first frames compile and upload
            ren_ms.append((time.perf_counter() - t0) * 1e3)
        if progress:
            progress()
    paper = TABLE1.get(key, [])
    s_ms, r_ms = statistics.median(sim_ms), statistics.median(ren_ms)
    return {
        "key": key, "preset": preset, "season": season,
        "objects": stats["objects"], "nodes": stats["nodes"], "triangles": stats["triangles"],
        "paper_objects": sum(r[1] for r in paper) or None,
        "paper_nodes": sum(r[2] for r in paper) or None,
        "paper_triangles": sum(r[3] for r in paper) or None,
        "sim_ms": s_ms, "sim_ms_p90": float(np.percentile(sim_ms, 90)), "sim_frames": steps, "frame_s": STEP,
        "sim_ms_min": min(sim_ms),
        "render_ms": r_ms, "render_ms_p90": float(np.percentile(ren_ms, 90)), "render_ms_min": min(ren_ms),
        "render_frames": frames,
        "fps": 1000.0 / (s_ms + r_ms),
        "sim_fps": 1000.0 / s_ms,
        "paper_fps": TABLE1_FPS.get(key),
    }


def run_bench(keys, width: int = 1280, height: int = 720, frames: int = 20, steps: int = 200, samples: int = 4,
              wind: float = 5.0, quiet: bool = False, emit=None) -> dict:
    """The Table 1 benchmark over ``keys`` (see :data:`treeanim.table1.ROWS`): a dict with the machine,
    the GL renderer and one row per key.

    Ctrl-C keeps the rows already measured: the result then holds those, with ``interrupted``
    True (the row being measured is dropped).

    Parameters
    ----------
    emit : callable, optional
        Called with text as soon as there is some to show: the table's head once the GL
        renderer is known (:func:`format_head`), then each row's line as it finishes
        (:func:`format_row`), so a long run shows its rows as they come.

    Raises
    ------
    InputError
        ``wind`` outside 0 … :data:`treeanim.physics.wind.MAX_SPEED` (checked before the GL
        context is made or any tree is loaded).
    GLUnavailable
        No OpenGL context to render with.
    """
    import datetime

    from tqdm import tqdm

    from ..physics.wind import MAX_SPEED

    try:
        float_within("--wind", wind, 0.0, MAX_SPEED, " m/s")
    except ValueError as e:
        raise InputError(str(e)) from None

    started = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
    result = {"date": started, "machine": machine_info(), "size": [width, height], "wind": wind,
              "paper_machine": "Core2 Duo 2.8 GHz, GeForce 9500 GT (2012)", "interrupted": False, "rows": []}
    with offscreen(width, height, samples) as off:
        with off.ctx:
            info = dict(off.ctx.info)
        result.update(gl_renderer=info.get("GL_RENDERER"), gl_version=info.get("GL_VERSION"),
                      gl_vendor=info.get("GL_VENDOR"), samples=off.samples)
        bar = tqdm(total=len(keys) * (steps + frames + 2), desc="bench", unit="step", disable=quiet, leave=False)

        def show(text: str) -> None:
            if emit is not None:
                with bar.external_write_mode():  # the bar steps aside for the line
                    emit(text)

        show(format_head(result))
        try:
            for key in keys:
                bar.set_description(f"bench {key}")
                row = bench_row(key, off, width, height, frames, steps, wind=wind, progress=bar.update)
                result["rows"].append(row)
                show(format_row(row))
        except KeyboardInterrupt:  # keep what finished
            result["interrupted"] = True
        finally:
            bar.close()
    return result


def format_head(result: dict) -> str:
    """The benchmark's machine line and the table's header."""
    m = result["machine"]
    w, h = result["size"]
    return "\n".join([
        f"{result['date']} — {m['cpu']}, {m['cores']} cores"
        + (f" (load {m['load_average'][0]:.2f} at start)" if m.get("load_average") else "")
        + f"; GL: {result['gl_renderer']} ({result['gl_version']}); {w}×{h}, {result['samples']}× MSAA; "
        f"wind {result['wind']:g} m/s",
        "",
        "| preset | objects (ours / paper) | nodes (ours / paper) | triangles (ours / paper) "
        "| sim ms/frame | render ms/frame | FPS (ours / paper) |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ])


def format_row(r: dict) -> str:
    """One row of the table (:func:`bench_row`'s dict) as a Markdown line."""

    def pair(a, b):
        return f"{a:,} / {b:,}" if b else f"{a:,} / —"

    name = r["key"].replace("@winter", " (winter)") if "@" in r["key"] else \
        r["key"] + (" (summer)" if r["key"] == "large_cherry" else "")
    pf = r["paper_fps"]
    return (f"| {name} | {pair(r['objects'], r['paper_objects'])} | {pair(r['nodes'], r['paper_nodes'])} "
            f"| {pair(r['triangles'], r['paper_triangles'])} | {r['sim_ms']:.1f} | {r['render_ms']:.1f} "
            f"| {r['fps']:.1f} / {pf if pf is not None else '—'} |")
