"""Live plots in the panel (issue 31), drawn with ImPlot: the pulled point's trace (its
displacement from rest over the last seconds) and the spectra of the wind at the canopy top, of
the trunk top's sway and of the grabbed point's (log-log, each over its total power, so their
shapes share one axis).

:class:`Signals` records, after every step, the time, the wind speed at the canopy top (above
the first trunk's base, at the tree's height), the trunk top's displacement and the traced
(grabbed) point's displacement from rest, over the last :data:`SECONDS` seconds.
:meth:`Signals.spectra` takes the power spectra of the wind speed, of the trunk top's sway and
of the grabbed point's (:func:`spectrum`), at most :data:`REFRESH` times a second of wall time (cached between); the
panel draws what they hold (:func:`draw_plots`).
"""

from __future__ import annotations

import time

import numpy as np

__all__ = ["Signals", "spectrum", "rest_point", "draw_plots", "SECONDS", "TRACE_SECONDS", "REFRESH"]

#: Simulated seconds the signals (and so the spectra) span.
SECONDS = 20.0
#: Seconds of the trace plot.
TRACE_SECONDS = 6.0
#: Spectra computed at most this many times a second (wall time).
REFRESH = 4.0
#: Samples kept (20 s at steps of 1/60 s × the slowest time scale, 0.05).
CAPACITY = 24_000


def spectrum(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The one-sided power spectral density of ``x`` sampled at times ``t``.

    Parameters
    ----------
    t : (K,) float
        Increasing sample times (s); resampled onto their median step.
    x : (K,) or (K, C) float
        The signal; its components' spectra are summed (a vector's power).

    Returns
    -------
    f : (F,) float
        Frequencies (Hz), the zero one left out (log axes).
    power : (F,) float
        Power per hertz (the signal's unit² / Hz) of the mean-removed, Hann-windowed signal.
    """
    t = np.asarray(t, float)
    if len(t) < 8:
        return np.zeros(0), np.zeros(0)
    x = np.asarray(x, float).reshape(len(t), -1)
    dt = float(np.median(np.diff(t)))
    grid = np.arange(t[0], t[-1] + 0.5 * dt, dt)
    y = np.stack([np.interp(grid, t, x[:, c]) for c in range(x.shape[1])], axis=1)
    y -= y.mean(axis=0)
    w = np.hanning(len(grid))[:, None]
    power = np.abs(np.fft.rfft(y * w, axis=0)) ** 2
    power = 2.0 * dt * power.sum(axis=1) / np.sum(w**2)
    return np.fft.rfftfreq(len(grid), dt)[1:], power[1:]


def rest_point(tree, obj: int, s: float) -> np.ndarray:
    """The point at fraction ``s`` of object ``obj``'s rest length (world)."""
    P = tree.rest_positions[tree.object_nodes(obj)]
    cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
    return np.array([np.interp(s * cum[-1], cum, P[:, c]) for c in range(3)])


def _point(sim, obj: int, s: float) -> np.ndarray:
    """Where the point at fraction ``s`` of ``obj`` is: the tree model's, or the paper's tip."""
    return sim.point_position(obj, s) if sim.model == "tree" else sim.tip_position(obj)


class Signals:
    """What the plots draw, recorded after every step over the last ``seconds``.

    Attributes
    ----------
    canopy_top : (3,) float
        Where the wind is measured: above the first trunk's base, at the tree's height.
    """

    def __init__(self, tree, seconds: float = SECONDS, capacity: int = CAPACITY) -> None:
        self.seconds = float(seconds)
        self.tree = tree
        base = tree.rest_positions[tree.object_start[0]]
        self.canopy_top = np.array([base[0], tree.rest_positions[:, 1].max(), base[2]])
        self.trunk_rest = rest_point(tree, 0, 1.0)
        self._t = np.zeros(capacity)
        self._x = np.zeros((capacity, 7))  # wind speed, trunk top (3), traced point (3)
        self._n = 0
        self._cache: tuple[float, int, dict] | None = None

    def clear(self) -> None:
        """Forget every sample."""
        self._n = 0
        self._cache = None

    def __len__(self) -> int:
        return self._n

    def record(self, sim, traced: tuple[int, float] | None, traced_at=None) -> None:
        """Record ``sim`` now: the wind at the canopy top, the trunk top and the point
        ``traced`` ((object, s), at ``traced_at`` if known) less their rest positions."""
        if self._n == len(self._t):  # full: forget what is older than the span (at least one)
            k = max(int(np.searchsorted(self._t, sim.time - self.seconds)), 1)
            self._t[: self._n - k], self._x[: self._n - k] = self._t[k:].copy(), self._x[k:].copy()
            self._n -= k
        row = self._x[self._n]
        row[0] = float(np.linalg.norm(sim.wind.sample(self.canopy_top[None], sim.time)[0]))
        row[1:4] = _point(sim, 0, 1.0) - self.trunk_rest
        if traced is None:
            row[4:] = np.nan
        else:
            at = _point(sim, *traced) if traced_at is None else traced_at
            row[4:] = at - rest_point(self.tree, *traced)
        self._t[self._n] = sim.time
        self._n += 1

    def forget_after(self, t: float) -> None:
        """Forget the samples after time ``t`` (the timeline resumed from an earlier state)."""
        self._n = int(np.searchsorted(self._t[: self._n], t + 1e-9))
        self._cache = None

    def window(self, seconds: float | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(times (K,), samples (K, 7): wind speed, trunk top, traced point) of the last
        ``seconds`` (None: :attr:`seconds`)."""
        t = self._t[: self._n]
        k = int(np.searchsorted(t, t[-1] - (seconds or self.seconds) - 1e-9)) if len(t) else 0
        return t[k:], self._x[k: self._n]

    def trace(self, seconds: float = TRACE_SECONDS) -> tuple[np.ndarray, np.ndarray]:
        """(times relative to now (s, ≤ 0), the traced point's displacement (K, 3) m) over the
        last ``seconds`` (no rows where nothing was traced)."""
        t, x = self.window(seconds)
        keep = np.isfinite(x[:, 4])
        return t[keep] - (t[-1] if len(t) else 0.0), x[keep, 4:]

    def spectra(self, now: float | None = None) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """{'wind': (f, power (m/s)²/Hz), 'sway': (f, power m²/Hz) of the trunk top, 'grabbed':
        (f, power m²/Hz) of the traced point (since it was grabbed)} of the samples kept; worked
        out again at most :data:`REFRESH` times a second of wall time ``now`` (None: read the
        clock) while samples come in."""
        now = time.perf_counter() if now is None else now
        if self._cache is None or (self._cache[1] != self._n and now - self._cache[0] >= 1.0 / REFRESH):
            t, x = self.window()
            held = np.isfinite(x[:, 4])
            self._cache = (now, self._n, {"wind": spectrum(t, x[:, 0]), "sway": spectrum(t, x[:, 1:4]),
                                          "grabbed": spectrum(t[held], x[held, 4:])})
        return self._cache[2]


def _peak(f: np.ndarray, p: np.ndarray) -> str:
    return f"{f[int(np.argmax(p))]:.2f} Hz" if len(p) and p.max() > 0 else "–"


def draw_plots(signals: Signals, width: float, height: float, shown: float | None = None) -> None:
    """Draw the trace and the spectra plots (inside the panel's window); ``shown``: the time of
    the state shown, marked on the trace when the timeline is scrubbed back."""
    from imgui_bundle import imgui, implot

    size = imgui.ImVec2(width, height)
    flags = implot.Flags_.no_menus | implot.Flags_.no_box_select
    t, d = signals.trace()
    if implot.begin_plot("grabbed point##trace", size, flags):
        implot.setup_axes("s", "m", implot.AxisFlags_.auto_fit, implot.AxisFlags_.auto_fit)
        implot.setup_axis_limits(implot.ImAxis_.x1, -TRACE_SECONDS, 0.0, implot.Cond_.always)
        implot.setup_legend(implot.Location_.north, implot.LegendFlags_.horizontal | implot.LegendFlags_.outside)
        if len(t) > 1:
            for c, name in enumerate("xyz"):
                implot.plot_line(name, np.ascontiguousarray(t), np.ascontiguousarray(d[:, c]))
        newest = signals.window()[0]
        if shown is not None and len(newest) and shown < newest[-1]:
            implot.plot_inf_lines("shown", np.array([shown - newest[-1]]))
        implot.end_plot()
    sp = signals.spectra()
    imgui.text_disabled(f"peaks: wind {_peak(*sp['wind'])}, trunk {_peak(*sp['sway'])}, "
                        f"grabbed {_peak(*sp['grabbed'])}")
    if implot.begin_plot("spectra, each ÷ its power##spectra", imgui.ImVec2(width, 1.2 * height), flags):
        implot.setup_axes("Hz", "1/Hz", implot.AxisFlags_.auto_fit, implot.AxisFlags_.auto_fit)
        implot.setup_legend(implot.Location_.north, implot.LegendFlags_.horizontal | implot.LegendFlags_.outside)
        implot.setup_axis_scale(implot.ImAxis_.x1, implot.Scale_.log10)
        implot.setup_axis_scale(implot.ImAxis_.y1, implot.Scale_.log10)
        for name, key in (("trunk top", "sway"), ("grabbed", "grabbed"), ("wind", "wind")):
            f, p = sp[key]
            ok = p > 0
            if ok.sum() > 1:  # shapes compared on one axis: each spectrum over its total power
                share = p[ok] / (p.sum() * (f[1] - f[0]))
                implot.plot_line(name, np.ascontiguousarray(f[ok]), np.ascontiguousarray(share))
        implot.end_plot()
