"""Pull-and-release of a single curved beam: the Lissajous / harmonograph traces of Fig. 4.

Hu, Chiba & He (2012), Fig. 4: a beam whose two translational modes have slightly different
natural frequencies and damping ratios, pulled sideways and let go, traces a harmonograph
figure — the sway turns from a line into an ellipse and round to the opposite diagonal as the
two modes drift out of phase, while it decays.

    .venv/bin/python examples/lissajous.py --out lissajous_out

writes ``fig4a.png`` (f_u = 0.75, f_w = 0.8, ζ_u = 0.045, ζ_w = 0.04), ``fig4b.png``
(f_u = 1.0, f_w = 1.1, ζ_u = 0.035, ζ_w = 0.03) and ``fig4.png`` (both side by side): the
beam tip's horizontal trace after the release. Needs matplotlib:
``.venv/bin/pip install -e '.[plots]'`` from the repository.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import treeanim as ta
from treeanim.model.build import ObjectSpec, assemble
from treeanim.offline.trace import PLOTS_HINT, pyplot, save_figure
from treeanim.physics.bending import rest_frames
from treeanim.physics.simulation import Simulation
from treeanim.physics.trace import trace_tips

CASES = {
    "fig4a": dict(f_u=0.75, f_w=0.8, zeta_u=0.045, zeta_w=0.04),
    "fig4b": dict(f_u=1.0, f_w=1.1, zeta_u=0.035, zeta_w=0.03),
}


def beam_tree():
    """The ``beam`` preset, or an equivalent curved beam when presets are not installed."""
    try:
        return ta.load_preset("beam")
    except Exception:  # noqa: BLE001
        n = 11
        s = np.linspace(0.0, 2.0, n)
        a = 0.175 * s  # a 20° arc over 2 m
        pts = np.stack([-np.cumsum(np.r_[0, np.diff(s)] * np.sin(a)), np.cumsum(np.r_[0, np.diff(s)] * np.cos(a)),
                        np.zeros(n)], 1)
        return assemble([ObjectSpec(pts, np.linspace(0.06, 0.02, n), "branch", 1)], name="beam")


def pull_and_release(f_u: float, f_w: float, zeta_u: float, zeta_w: float, angle_deg: float = 35.0,
                     deflection: float = 0.1, seconds: float = 40.0, dt: float = 1 / 120):
    """Pull the beam's tip between its u and w axes, release it, and record the tip.

    Parameters
    ----------
    f_u, f_w, zeta_u, zeta_w : float
        The two translational modes (mode v, the twist, takes f_u and ζ_u).
    angle_deg : float
        Pull direction, degrees from u towards w.
    deflection : float
        Static tip deflection while held, as a fraction of the beam's length (the force is
        scaled to give it).
    seconds, dt : float
        Recording time after the release and its step.

    Returns
    -------
    times : (T,) float
    xz : (T, 2) float
        Tip displacement from rest along world x and z (horizontal), metres.
    sim : Simulation
    """
    tree = beam_tree()
    sim = Simulation(tree, model="paper")  # the paper's modal oscillators, set per object
    sim.modes.f[0] = (f_u, f_u, f_w)
    sim.modes.zeta[0] = (zeta_u, zeta_u, zeta_w)
    frame = rest_frames(tree)[0]  # the beam's rest (u, v, w), Eq. 1
    u, w = frame[:, 0], frame[:, 2]
    a = np.radians(angle_deg)
    direction = np.cos(a) * u + np.sin(a) * w
    tip_rest = tree.rest_positions[-1]
    length = float(np.sum(np.linalg.norm(np.diff(tree.rest_positions, axis=0), axis=1)))
    # Scale the force to the wanted static deflection (a held object sits at its static pose).
    force = 1.0
    for _ in range(30):
        sim.reset()
        sim.modes.f[0] = (f_u, f_u, f_w)
        sim.modes.zeta[0] = (zeta_u, zeta_u, zeta_w)
        sim.pull(0, force * direction)
        sim.step(dt)
        d = float(np.linalg.norm(sim.tip_position(0) - tip_rest))
        if abs(d / (deflection * length) - 1) < 1e-3:
            break
        force *= deflection * length / max(d, 1e-12)
    for _ in range(int(round(1.0 / dt))):  # hold for a second
        sim.step(dt)
    sim.release()
    times, tips = trace_tips(sim, 0, seconds, dt)
    disp = tips[:, 0, :] - tip_rest
    return times - times[0], disp[:, [0, 2]], sim


def plot(ax, times, xz, title):
    """Draw one trace, darkening with time like a pen on a harmonograph."""
    from matplotlib.collections import LineCollection

    pts = xz * 100.0  # cm
    segs = np.stack([pts[:-1], pts[1:]], axis=1)
    lc = LineCollection(segs, cmap="viridis", linewidths=0.9)
    lc.set_array(times[:-1])
    ax.add_collection(lc)
    ax.plot(*pts[0], "o", color="crimson", ms=5, label="released here")
    lim = 1.08 * np.abs(pts).max()
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("x (cm)")
    ax.set_ylabel("z (cm)")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right", fontsize=8)
    return lc


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="Fig. 4: Lissajous traces of a pulled and released beam")
    ap.add_argument("--out", type=Path, default=Path("lissajous_out"), help="output folder for the PNGs")
    ap.add_argument("--angle", type=float, default=35.0, help="pull direction, degrees from u towards w")
    ap.add_argument("--seconds", type=float, default=25.0, help="seconds recorded after the release")
    args = ap.parse_args(argv)
    plt = pyplot()
    if plt is None:
        print(f"lissajous.py {PLOTS_HINT}", file=sys.stderr)
        return 1

    args.out.mkdir(parents=True, exist_ok=True)
    results = {}
    for name, p in CASES.items():
        times, xz, _ = pull_and_release(**p, angle_deg=args.angle, seconds=args.seconds)
        results[name] = (times, xz, p)
        title = (f"f_u = {p['f_u']}, f_w = {p['f_w']}, ζ_u = {p['zeta_u']}, ζ_w = {p['zeta_w']}")
        fig, ax = plt.subplots(figsize=(5.2, 5.2), dpi=120)
        lc = plot(ax, times, xz, title)
        fig.colorbar(lc, ax=ax, shrink=0.8, label="time after release (s)")
        save_figure(fig, args.out / f"{name}.png")
        print(f"{name}: {title}; wrote {args.out / (name + '.png')}")
    fig, axes = plt.subplots(1, 2, figsize=(10, 5), dpi=120)
    for ax, (name, (times, xz, p)) in zip(axes, results.items()):
        plot(ax, times, xz, f"({name[-1]}) f_u={p['f_u']}, f_w={p['f_w']}, ζ_u={p['zeta_u']}, ζ_w={p['zeta_w']}")
    fig.suptitle("Tip trace of a curved beam after pull and release (cf. Hu et al. 2012, Fig. 4)")
    save_figure(fig, args.out / "fig4.png")
    print(f"wrote {args.out / 'fig4.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
