"""``treeanim trace``: pull (or drag) one object's tip, let go, and record its free swing (the
paper's Figs. 1 and 4) as CSV and, with matplotlib, a plot."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..files import atomic_path
from ..validate import positive_float

#: What to install for plots (``trace --plot`` and the examples), from the repository.
PLOTS_HINT = "needs matplotlib: .venv/bin/pip install -e '.[plots]' (from the repository)"


@dataclass
class TraceResult:
    """A tip trace after release: ``times`` (T,) from 0 at release, ``tips`` (T, 3) world;
    ``f`` and ``zeta`` the object's modes (u, v, w) on the paper's model, None on the tree model
    (whose frequencies are the whole structure's)."""

    times: np.ndarray
    tips: np.ndarray
    rest: np.ndarray
    held: np.ndarray
    obj: int
    kind: str
    f: np.ndarray | None
    zeta: np.ndarray | None


def run_trace(sim, obj: int, force, hold: float, seconds: float, rate: float, drag=None) -> TraceResult:
    """Pull object ``obj``'s tip with ``force`` (N, world) — or, with ``drag`` (a world point,
    the tree model), drag the tip toward it (:meth:`Simulation.drag`) — for ``hold`` seconds
    (the held object sits at its static deflection; the rest of the tree settles), let go, and
    record the tip for ``seconds`` at ``rate`` samples per second.

    Raises
    ------
    InputError
        ``seconds`` or ``rate`` not finite and positive, so small that fewer than 2 samples
        would follow the release, or so large that the hold or the trace would take more than
        a quarter of :data:`~treeanim.physics.trace.MAX_TRACE_VALUES` samples (checked before
        anything is simulated or allocated).
    """
    from ..driver import FrameDriver
    from ..scripted import Drag, Pull, Schedule

    try:
        positive_float("--seconds", seconds), positive_float("--rate", rate)
    except ValueError as e:
        raise InputError(str(e)) from None
    from ..physics.trace import MAX_TRACE_VALUES

    samples = seconds * rate + 1  # the release and every sample after it
    if not 4 * max(samples, hold * rate) <= MAX_TRACE_VALUES:  # a time and a point a sample
        raise InputError(f"--seconds {seconds:g} and --hold {hold:g} at --rate {rate:g} Hz are {samples:.3g} samples; "
                         f"at most {MAX_TRACE_VALUES // 4:,}")
    samples = int(round(samples))
    if samples < 2:
        raise InputError(f"--seconds {seconds:g} at --rate {rate:g} Hz gives {samples} sample after release; "
                         f"a trace needs at least 2 samples")
    tree = sim.tree
    tip = int(tree.object_start[obj] + tree.object_count[obj] - 1)
    hand = Schedule([Drag(obj, tuple(drag), 0.0, np.inf) if drag is not None
                     else Pull(obj, tuple(force), 0.0, np.inf)])
    driver = FrameDriver.at_rate(rate)  # the offline commands' frames, sampled at the rate
    for _ in driver.frames(sim, max(1, int(round(hold * rate))) + 1, hand):
        pass
    held = sim.tip_position(obj)
    hand.release(sim)
    times, tips = np.empty(samples), np.empty((samples, 3))
    for k in driver.frames(sim, samples):
        times[k], tips[k] = sim.time, sim.tip_position(obj)
    f = zeta = None
    if sim.model == "paper":
        f, zeta = np.array(sim.modes.f[obj], float), np.array(sim.modes.zeta[obj], float)
    return TraceResult(times - times[0], tips, np.asarray(tree.rest_positions[tip], float), held, obj,
                       str(tree.kind[obj]), f, zeta)


def write_trace_csv(path: Path, trace: TraceResult) -> None:
    """``t,x,y,z`` (seconds after release, world metres), written beside ``path`` and renamed."""
    data = np.column_stack([trace.times, trace.tips])
    with atomic_path(path, ".csv") as tmp:
        np.savetxt(tmp, data, delimiter=",", header="t,x,y,z", comments="", fmt=["%.6f", "%.9f", "%.9f", "%.9f"])


def plot_trace(path: Path, trace: TraceResult, title: str = "") -> None:
    """The horizontal trace of the tip (x–z displacement from rest, equal aspect), coloured by
    time after release, in the manner of the paper's Figs. 1 and 4."""
    from matplotlib.collections import LineCollection

    plt = pyplot()

    d = trace.tips - trace.rest
    x, z = d[:, 0] * 100, d[:, 2] * 100  # cm
    pts = np.column_stack([x, z])
    segs = np.stack([pts[:-1], pts[1:]], axis=1)
    t = trace.times
    fig, ax = plt.subplots(figsize=(6.4, 6.0), dpi=150)
    age = t[:-1] / max(t[-1], 1e-9)
    cmap = plt.get_cmap("viridis")
    colors = cmap(age)
    colors[:, 3] = 1.0 - 0.65 * age  # fade as it dies away
    lc = LineCollection(segs, colors=colors, linewidths=1.1, capstyle="round")
    ax.add_collection(lc)
    ax.plot([0], [0], "+", color="0.2", ms=12, mew=1.5, label="rest")
    ax.plot([x[0]], [z[0]], "o", color=cmap(0.0), ms=6, label="release")
    span = max(np.ptp(x), np.ptp(z), 1e-6)
    cx, cz = 0.5 * (x.max() + x.min()), 0.5 * (z.max() + z.min())
    half = 0.55 * span
    ax.set_xlim(cx - half, cx + half)
    ax.set_ylim(cz - half, cz + half)
    ax.set_aspect("equal")
    ax.set_xlabel("tip displacement x (cm)")
    ax.set_ylabel("tip displacement z (cm)")
    ax.grid(True, color="0.9", lw=0.6)
    ax.legend(loc="upper right", frameon=False, fontsize=8)
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(0, t[-1]))
    fig.colorbar(sm, ax=ax, fraction=0.046, pad=0.04, label="time after release (s)")
    sub = f"object {trace.obj} ({trace.kind})"
    if trace.f is not None:
        f, z_ = trace.f, trace.zeta
        sub += f": f u,v,w = {f[0]:.3f}, {f[1]:.3f}, {f[2]:.3f} Hz; ζ = {z_[0]:.3f}, {z_[1]:.3f}, {z_[2]:.3f}"
    ax.set_title((title + "\n" if title else "") + sub, fontsize=9)
    save_figure(fig, path)


def pyplot():
    """matplotlib's pyplot on the Agg backend (files, no window), or None where matplotlib is
    not installed (:data:`PLOTS_HINT` says how to install it)."""
    try:
        import matplotlib
    except ImportError:
        return None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: str | Path) -> Path:
    """Lay out ``fig``, write it to ``path`` atomically (the format from its suffix) and close it."""
    import matplotlib.pyplot as plt

    path = Path(path)
    fig.tight_layout()
    suffix = path.suffix.lower()
    try:
        with atomic_path(path, suffix) as tmp:
            fig.savefig(tmp, format=suffix[1:])
    finally:
        plt.close(fig)
    return path


def zero_crossing_frequency(t: np.ndarray, x: np.ndarray) -> float:
    """Frequency (Hz) of an oscillating signal from its mean zero-crossing interval."""
    x = np.asarray(x, float)
    s = np.signbit(x)
    i = np.flatnonzero(s[1:] != s[:-1])
    if len(i) < 3:
        return float("nan")
    tz = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    return float(1.0 / (2.0 * np.mean(np.diff(tz))))
