"""Shared fixtures (small hand-built trees, one EGL offscreen context per test session), the
Hypothesis profile, and the markers: ``gl`` and ``window`` by module, ``slow`` from the measured
durations in tests/durations.json (``pytest --store-durations`` writes them)."""

from __future__ import annotations

import dataclasses
import json
import resource
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

from treeanim.model.build import ObjectSpec, assemble
from treeanim.model.tree import Lamina

# --------------------------------------------------------------------------- hypothesis
#: Every property test draws the same examples on every run (a seed from the test itself), has no
#: deadline (a loaded 2-core machine made one flaky) and keeps no example database (no run
#: replays another's failures). A test sets only its own ``max_examples``.
settings.register_profile("treeanim", derandomize=True, deadline=None, max_examples=50, database=None,
                          suppress_health_check=[HealthCheck.too_slow], print_blob=True)
settings.load_profile("treeanim")

# --------------------------------------------------------------------------- markers
#: Modules that draw through OpenGL (EGL offscreen; test_app: the app on a headless window), and
#: those that open a window (Xvfb).
GL_MODULES = {"test_render_gl", "test_render_look", "test_render_uniforms", "test_junctions", "test_offline",
              "test_examples", "test_app", "test_scenes_gl", "test_render_setting"}
WINDOW_MODULES = {"test_app_window", "test_render_window"}
#: Each test's measured CPU seconds (node id -> s), written by ``pytest --store-durations``.
DURATIONS = Path(__file__).with_name("durations.json")
#: A test measured at this many CPU seconds or more is marked ``slow``: ``-m "not slow"`` is the
#: quick loop (0.2 s keeps it under 30 s of CPU; at 0.4 s it took 43 s, at 1 s a minute).
SLOW_SECONDS = 0.2


def pytest_addoption(parser):
    parser.addoption("--store-durations", action="store_true",
                     help="measure every test that passes and merge its seconds into tests/durations.json, "
                          "from which the 'slow' mark is derived")


def pytest_configure(config):
    if config.getoption("store_durations"):
        config.pluginmanager.register(DurationRecorder(config.rootpath), "treeanim-durations")


def load_durations(path: Path = DURATIONS) -> dict[str, float]:
    """The measured seconds of each test, by node id.

    Parameters
    ----------
    path : Path
        A JSON object of node id -> seconds, as :class:`DurationRecorder` writes it.

    Returns
    -------
    dict of str to float
        Empty when the file does not exist.
    """
    return json.loads(path.read_text()) if path.is_file() else {}


def pytest_collection_modifyitems(config, items):
    durations = load_durations()
    for item in items:
        module = item.path.stem
        if module in GL_MODULES:
            item.add_marker(pytest.mark.gl)
        if module in WINDOW_MODULES:
            item.add_marker(pytest.mark.window)
        if durations.get(item.nodeid, 0.0) >= SLOW_SECONDS:
            item.add_marker(pytest.mark.slow)


def pytest_report_collectionfinish(config, items):
    durations = load_durations()
    n = sum(item.nodeid not in durations for item in items)
    if n:
        return f"{n} test(s) not in tests/durations.json (counted quick): measure them with --store-durations"


def cpu_seconds() -> float:
    """CPU seconds used so far by this process (all its threads, llvmpipe's included) and by its
    children that have been waited for (the command-line tests' subprocesses)."""
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


class DurationRecorder:
    """The ``--store-durations`` plugin: each passing test's CPU seconds, merged into
    :data:`DURATIONS` at the end of the session.

    A test's seconds are its own setup, call and teardown, plus the setup of every shared
    (module- or session-scoped) fixture it uses, whichever test happened to create it: run on its
    own, or with the quick loop, a test pays for those. So the marks do not depend on the order
    the tests ran in, and CPU time (not wall time) keeps them from depending on how busy the
    machine was.

    Parameters
    ----------
    rootpath : Path
        The rootdir, which node ids are relative to.
    """

    def __init__(self, rootpath: Path) -> None:
        self.rootpath = rootpath
        self.shared: dict[tuple, float] = {}  # (scope node id, fixture, param) -> seconds of its own setup
        self.own: dict[str, float] = {}
        self.uses: dict[str, list[tuple]] = {}
        self.passed: set[str] = set()
        self.collected: set[str] = set()
        self._nested: list[float] = []  # shared setups in progress: seconds of the shared ones inside each
        self._in_phase = 0.0  # shared setup seconds within the current phase (not the test's own)

    def pytest_itemcollected(self, item):
        self.collected.add(item.nodeid)

    @pytest.hookimpl(wrapper=True)
    def pytest_fixture_setup(self, fixturedef, request):
        if fixturedef.scope == "function":
            return (yield)
        t0 = cpu_seconds()
        self._nested.append(0.0)
        try:
            return (yield)
        finally:
            total = cpu_seconds() - t0
            own = total - self._nested.pop()
            if self._nested:
                self._nested[-1] += total
            key = (request.node.nodeid, fixturedef.argname, repr(getattr(request, "param", None)))
            self.shared[key] = self.shared.get(key, 0.0) + own
            self._in_phase += own

    def _timed(self, item):
        """Add the CPU seconds of the phase this wraps to ``item``'s own."""
        self._in_phase = 0.0
        t0 = cpu_seconds()
        try:
            return (yield)
        finally:
            spent = cpu_seconds() - t0 - self._in_phase
            self.own[item.nodeid] = self.own.get(item.nodeid, 0.0) + spent

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_setup(self, item):
        params = item.callspec.params if hasattr(item, "callspec") else {}
        scopes = [node.nodeid for node in item.listchain()]
        self.uses[item.nodeid] = [(scope, name, repr(params.get(name))) for name in item.fixturenames for scope in scopes]
        return (yield from self._timed(item))

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_call(self, item):
        return (yield from self._timed(item))

    @pytest.hookimpl(wrapper=True)
    def pytest_runtest_teardown(self, item, nextitem):
        return (yield from self._timed(item))

    def pytest_runtest_logreport(self, report):
        if report.when == "call" and report.passed:
            self.passed.add(report.nodeid)

    def pytest_sessionfinish(self, session):
        data = load_durations()
        files = {nodeid.split("::")[0] for nodeid in self.collected}
        data = {nodeid: s for nodeid, s in data.items()
                if (self.rootpath / nodeid.split("::")[0]).is_file()
                and (nodeid.split("::")[0] not in files or nodeid in self.collected)}
        for nodeid in self.passed:
            shared = sum(self.shared.get(key, 0.0) for key in self.uses.get(nodeid, ()))
            data[nodeid] = round(max(self.own[nodeid], 0.0) + shared, 2)
        DURATIONS.write_text(json.dumps(dict(sorted(data.items())), indent=0) + "\n")

    def pytest_terminal_summary(self, terminalreporter):
        terminalreporter.write_line(f"stored the durations of {len(self.passed)} test(s) in {DURATIONS}")


def rot(axis, angle):
    """The rotation matrix of ``angle`` radians about ``axis`` (the identity for a zero axis)."""
    axis = np.asarray(axis, float)
    n = np.linalg.norm(axis)
    if n == 0:
        return np.eye(3)
    axis = axis / n
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def identity(tree):
    """(N, 3, 3) identity rotations: every node of ``tree`` at rest."""
    return np.broadcast_to(np.eye(3), (tree.n_nodes, 3, 3))


def rest_pose(tree):
    """``tree``'s rest pose as a renderer takes it: (positions, rotations)."""
    return tree.rest_positions, identity(tree)


class Uniform:
    """A steady uniform wind U (m/s) everywhere (only ``sample`` is needed)."""

    def __init__(self, U):
        self.U = np.asarray(U, float)

    def sample(self, points, t):
        return np.tile(self.U, (len(points), 1))


def ovate_lamina(k: int = 24, curl: float = 0.12) -> Lamina:
    """An ovate, pointed leaf outline (midrib length 1), fan-triangulated from its base."""
    s = np.linspace(0.0, 1.0, k // 2 + 1)
    y = s
    half = 0.42 * np.sin(np.pi * s) ** 0.8 * (1.0 - 0.35 * s)
    right = np.stack([half, y], 1)[1:-1]
    left = np.stack([-half, y], 1)[1:-1][::-1]
    outline = np.concatenate([[[0.0, 0.0]], right, [[0.0, 1.0]], left])
    n = len(outline)
    tris = np.stack([np.zeros(n - 2, int), np.arange(1, n - 1), np.arange(2, n)], 1)
    return Lamina("ovate", outline, tris, curl)


def _curve(base, direction, length, n, bend=0.0, bend_dir=(0.0, -1.0, 0.0)):
    """n points from ``base`` along ``direction``, curving gently towards ``bend_dir``."""
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    g = np.asarray(bend_dir, float)
    pts = [np.asarray(base, float)]
    step = length / (n - 1)
    for _ in range(n - 1):
        pts.append(pts[-1] + step * d)
        d = d + bend * g
        d = d / np.linalg.norm(d)
    return np.array(pts)


def small_tree(leaves_per_twig: int = 4, seed: int = 3) -> "Tree":  # noqa: F821
    """A ~2.5 m tree: trunk, 5 branches, 3 twigs each, leaves on the twigs (hand-built)."""
    rng = np.random.default_rng(seed)
    specs: list[ObjectSpec] = []
    trunk = _curve((0, 0, 0), (0.03, 1, 0.0), 1.6, 6)
    specs.append(ObjectSpec(trunk, np.linspace(0.16, 0.07, 6), "branch", 1))
    for b in range(5):
        at = 2 + b % 4
        az = 2 * np.pi * b / 5 + 0.3
        d = (np.cos(az), 0.9, np.sin(az))
        pts = _curve(trunk[at], d, 1.0, 5, bend=0.08)
        specs.append(ObjectSpec(pts, np.linspace(0.06, 0.02, 5), "branch", 2, parent=0, attach=at))
        bi = len(specs) - 1
        for t in range(3):
            tat = 2 + t % 3
            az2 = az + (t - 1) * 0.9
            d2 = (np.cos(az2), 0.6 + 0.3 * t, np.sin(az2))
            tw = _curve(pts[tat], d2, 0.55, 4, bend=0.1)
            specs.append(ObjectSpec(tw, np.linspace(0.02, 0.008, 4), "branch", 3, parent=bi, attach=tat))
            ti = len(specs) - 1
            for leaf in range(leaves_per_twig):
                lat = 1 + leaf % 3
                dl = rng.normal(size=3) + np.array([0.0, 0.3, 0.0])
                pet = _curve(tw[lat], dl, 0.05, 4, bend=0.15)
                wl = np.cross(dl, rng.normal(size=3))
                specs.append(ObjectSpec(pet, np.full(4, 0.004), "leaf", 4, parent=ti, attach=lat,
                                        w=wl, lamina_length=0.16))
    return assemble(specs, name="small_test", lamina=ovate_lamina(), petiole_sides=4, seed=seed,
                    winter_leaves=4)


def grass_patch(n: int = 60, seed: int = 5) -> "Tree":  # noqa: F821
    """A patch of ``n`` grass blades (4 nodes each) on a 1 m square."""
    rng = np.random.default_rng(seed)
    specs = []
    for _ in range(n):
        base = (rng.uniform(-0.5, 0.5), 0.0, rng.uniform(-0.5, 0.5))
        lean = rng.normal(size=3) * 0.2
        pts = _curve(base, (lean[0], 1.0, lean[2]), rng.uniform(0.25, 0.4), 4, bend=0.15,
                     bend_dir=(lean[0], -1.0, lean[2]))
        specs.append(ObjectSpec(pts, np.array([0.02, 0.018, 0.012, 0.005]), "blade", 1))
    return assemble(specs, name="grass_test", seed=seed)


def beam_tree() -> "Tree":  # noqa: F821
    """One curved beam (the 'beam' preset's shape)."""
    pts = _curve((0, 0, 0), (0.2, 1, 0), 2.0, 9, bend=0.05, bend_dir=(1.0, 0.0, 0.0))
    return assemble([ObjectSpec(pts, np.linspace(0.1, 0.03, 9), "branch", 1)], name="beam_test")


def twig_tree(length: float = 0.6) -> "Tree":  # noqa: F821
    """A 1 m trunk carrying one straight one-segment twig along +x at its top."""
    trunk = _curve((0, 0, 0), (0, 1, 0), 1.0, 3)
    twig = np.array([trunk[2], trunk[2] + (length, 0.0, 0.0)])
    return assemble([ObjectSpec(trunk, np.linspace(0.08, 0.05, 3), "branch", 1),
                     ObjectSpec(twig, np.array([0.03, 0.015]), "branch", 2, parent=0, attach=2)],
                    name="twig_test")


@pytest.fixture(scope="session")
def tree():
    return small_tree()


@pytest.fixture(scope="session")
def grass():
    return grass_patch()


@pytest.fixture(scope="session")
def offscreen():
    """One EGL context for the whole session (creating contexts is the slow part)."""
    from treeanim.render.offscreen import OffscreenRenderer

    off = OffscreenRenderer(160, 120, samples=4)
    yield off
    off.release()


# ---------------------------------------------------------------------------- the headless app
@pytest.fixture(scope="module")
def cherry():
    """The small cherry, generated once for the module and read-only (its arrays cannot be
    written): each app gets a Tree of its own over the same arrays."""
    import treeanim as ta

    tree = ta.load_preset("small_cherry")
    for f in dataclasses.fields(tree):
        value = getattr(tree, f.name)
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
    return tree


@pytest.fixture
def no_display(monkeypatch):
    """No X or Wayland display for the app: whatever needed one would fail."""
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)


@pytest.fixture()
def viewer(cherry, no_display):
    """An app of its own for each test: a headless window (no MSAA, as the viewer on a
    software rasteriser) and a viewer of the small cherry at rest, calm, the tree model, panel
    hidden, 480 × 360, framed, one frame drawn (with no display: see ``no_display``)."""
    from app_helpers import H, W, open_viewer
    from treeanim.app.headless import HeadlessWindow

    yield from open_viewer(HeadlessWindow(W, H), dataclasses.replace(cherry))
