"""Scripted runs: pulls and drags scheduled on the command line hold and let go at their times;
--drag parses and refuses bad input with one line; --paper selects the paper's model."""

import numpy as np
import pytest

import treeanim as ta
from treeanim import cli, options
from treeanim.scripted import Drag, Pull, check_pulls, frames, parse_drag, parse_pull


class Recorder:
    """A stand-in for a Simulation that records what is held at each step (as the tree model
    does: release(i) lets go of object i's pull and drag)."""

    def __init__(self):
        self.held, self.time, self.log = {}, 0.0, []
        self.dragging = None
        self.drags = 0

    def pull(self, i, force):
        self.held[i] = tuple(force)

    def drag(self, i, target, s=1.0):
        self.dragging = (i, tuple(target), s)
        self.drags += 1

    def release(self, i=None):
        if i is None:
            self.held.clear()
            self.dragging = None
        else:
            self.held.pop(i, None)
            if self.dragging is not None and self.dragging[0] == i:
                self.dragging = None

    def step(self, dt):
        self.log.append((self.time, dict(self.held), self.dragging))
        self.time += dt


def held_at(log, t):
    return next(h for t0, h, _ in reversed(log) if t0 <= t + 1e-9)


def dragged_at(log, t):
    return next(d for t0, _, d in reversed(log) if t0 <= t + 1e-9)


def test_overlapping_and_back_to_back_pulls():
    pulls = [parse_pull("0:1,0,0@0-2"), parse_pull("1:0,0,2@1-3"), parse_pull("0:0,-5,0@2-2.5")]
    rec = Recorder()
    list(frames(rec, 40, 10, pulls, step=0.05))
    assert held_at(rec.log, 0.5) == {0: (1.0, 0.0, 0.0)}
    assert held_at(rec.log, 1.5) == {0: (1.0, 0.0, 0.0), 1: (0.0, 0.0, 2.0)}
    assert held_at(rec.log, 2.2) == {0: (0.0, -5.0, 0.0), 1: (0.0, 0.0, 2.0)}
    assert held_at(rec.log, 2.7) == {1: (0.0, 0.0, 2.0)}
    assert held_at(rec.log, 3.5) == {}
    assert rec.held == {}, "everything is let go at the end"


@pytest.mark.parametrize("fps,per_frame", [(7, 9), (24, 3), (30, 2), (60, 1), (250, 1)])
def test_frames_land_on_their_times_in_equal_steps(fps, per_frame):
    """The frame driver's offline policy (treeanim.driver.step_for): equal steps of at most
    1/60 s, a whole number of them a frame, so every frame lands on its time."""
    rec = Recorder()
    times = [rec.time for _ in frames(rec, 2 * fps, fps, [])]
    assert len(times) == 2 * fps
    np.testing.assert_allclose(times, np.arange(2 * fps) / fps, atol=1e-9)
    steps = np.diff([t for t, _, _ in rec.log])
    np.testing.assert_allclose(steps, 1 / (fps * per_frame), rtol=1e-9)
    assert steps.max() <= 1 / 60 + 1e-12


def test_scripted_pull_matches_hand_stepping():
    """The same pull scheduled by frames() and done by hand gives the same motion."""
    tree = ta.load_preset("beam")
    a, b = ta.Simulation(tree), ta.Simulation(tree)
    moved = 0.0
    for k in frames(a, 40, 20, [Pull(0, (10.0, 0.0, 5.0), 0.25, 1.0)], step=0.05):
        moved = max(moved, np.abs(a.positions - tree.rest_positions).max())
    t = 0.0
    while t < 1.95 - 1e-9:
        if 0.25 - 1e-9 <= t < 1.0 - 1e-9:
            b.pull(0, (10.0, 0.0, 5.0))
        else:
            b.release()
        b.step(0.05)
        t += 0.05
    np.testing.assert_allclose(a.positions, b.positions, atol=1e-9)
    assert moved > 1e-2


@pytest.mark.parametrize("text", ["0:1,2@0-1", "x:1,2,3@0-1", "0:1,2,3@2-1", "0:1,2,3", "0:nan,0,0@0-1"])
def test_bad_pull_refused(text):
    with pytest.raises(ValueError, match="--pull"):
        parse_pull(text)


def test_drags_hold_one_at_a_time_beside_pulls_on_the_same_object():
    """A drag holds its target from T0 to T1 (handed over once, not every step); a pull on the
    same object that ends meanwhile does not let go of the drag, nor the drag's end of the pull."""
    items = [parse_drag("0:1,2,3@0-2"), parse_pull("0:5,0,0@1-1.5"), parse_drag("1@0.5:0,1,0@2-3"),
             parse_pull("1:0,0,1@2.5-3.5")]
    rec = Recorder()
    list(frames(rec, 40, 10, items, step=0.05))
    assert dragged_at(rec.log, 0.5) == (0, (1.0, 2.0, 3.0), 1.0) and held_at(rec.log, 0.5) == {}
    assert dragged_at(rec.log, 1.2) == (0, (1.0, 2.0, 3.0), 1.0) and held_at(rec.log, 1.2) == {0: (5.0, 0.0, 0.0)}
    assert dragged_at(rec.log, 1.7) == (0, (1.0, 2.0, 3.0), 1.0) and held_at(rec.log, 1.7) == {}
    assert dragged_at(rec.log, 2.2) == (1, (0.0, 1.0, 0.0), 0.5)
    assert dragged_at(rec.log, 2.7) == (1, (0.0, 1.0, 0.0), 0.5) and held_at(rec.log, 2.7) == {1: (0.0, 0.0, 1.0)}
    assert dragged_at(rec.log, 3.2) is None and held_at(rec.log, 3.2) == {1: (0.0, 0.0, 1.0)}
    assert rec.drags == 3, "each drag is handed over once (and again after the pull's release)"
    assert rec.held == {} and rec.dragging is None, "everything is let go at the end"


def test_a_scripted_drag_moves_the_beams_tip_toward_the_target():
    sim = ta.Simulation(ta.load_preset("beam"))
    tip = sim.tip_position(0)
    target = tip + [0.1, 0.0, 0.0]
    for _ in frames(sim, 20, 10, [Drag(0, tuple(target), 0.0, 2.5)]):
        pass
    assert np.linalg.norm(sim.tip_position(0) - target) < 0.3 * 0.1
    assert not sim.drags, "let go at the end"


@pytest.mark.parametrize("text,drag", [
    ("0:1,2,3@0-1", Drag(0, (1.0, 2.0, 3.0), 0.0, 1.0, 1.0)),
    (" 12 @ 0.25 : -1,0.5,2e-1 @ 0.5 - 2 ", Drag(12, (-1.0, 0.5, 0.2), 0.5, 2.0, 0.25)),
    ("3@0:0,0,0@1-1.5", Drag(3, (0.0, 0.0, 0.0), 1.0, 1.5, 0.0)),
])
def test_drag_parses(text, drag):
    assert parse_drag(text) == drag


@pytest.mark.parametrize("text", ["0:1,2@0-1", "x:1,2,3@0-1", "0:1,2,3@2-1", "0:1,2,3", "0:nan,0,0@0-1",
                                  "0@1.5:1,2,3@0-1", "0@x:1,2,3@0-1", "-1:1,2,3@0-1", "0@-0.1:1,2,3@0-1"])
def test_bad_drag_refused(text):
    with pytest.raises(ValueError, match="--drag") as err:
        parse_drag(text)
    assert "\n" not in str(err.value)


def test_check_pulls_refuses_drags_on_the_paper_model_and_overlapping_drags():
    check_pulls([parse_drag("0:0,1,0@0-1"), parse_drag("0:0,1,0@1-2")], 1)
    with pytest.raises(ValueError, match="--drag needs the tree model"):
        check_pulls([parse_drag("0:0,1,0@0-1")], 1, model="paper")
    with pytest.raises(ValueError, match="overlap"):
        check_pulls([parse_drag("0:0,1,0@0-1"), parse_drag("0:0,1,0@0.5-2")], 1)
    with pytest.raises(ValueError, match="--drag on object 3: the tree has objects 0 to 0"):
        check_pulls([parse_drag("3:0,1,0@0-1")], 1)


def _one_line_error(capsys, argv):
    try:
        code = cli.main(argv)
    except SystemExit as e:  # argparse
        code = e.code
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    return err


@pytest.mark.parametrize("argv,words", [
    (["render", "beam", "--drag", "0-1,2,3@0-1", "--out", "x.png"], "expected OBJECT[@S]:X,Y,Z@T0-T1"),
    (["render", "beam", "--drag", "0:1,2@0-1", "--out", "x.png"], "three finite numbers"),
    (["export", "beam", "--drag", "0@2:1,2,3@0-1", "--out", "x.glb"], "S in [0, 1]"),
    (["render", "beam", "--drag", "1:0,1,0@0-1", "--out", "x.png"], "--drag on object 1"),
    (["render", "beam", "--paper", "--drag", "0:0,1,0@0-1", "--out", "x.png"], "--drag needs the tree model"),
    (["export", "beam", "--drag", "0:0,1,0@0-1", "--drag", "0:0,1,0@0.5-2", "--out", "x.glb"], "overlap"),
    (["trace", "beam", "--paper", "--drag", "0,1,0", "--out", "t.csv"], "--drag needs the tree model"),
    (["trace", "beam", "--drag", "0,1", "--out", "t.csv"], "three finite numbers"),
    (["trace", "beam", "--pull", "1,0,0", "--drag", "0,1,0", "--out", "t.csv"], "not allowed with"),
])
def test_bad_drag_on_the_command_line_is_one_line(tmp_path, monkeypatch, capsys, argv, words):
    monkeypatch.chdir(tmp_path)
    assert words in _one_line_error(capsys, argv)
    assert list(tmp_path.iterdir()) == [], "no file is left behind"


@pytest.mark.parametrize("extra,model", [([], "tree"), (["--paper"], "paper")])
def test_paper_selects_the_papers_model(extra, model):
    args = cli.build_parser().parse_args(["render", "beam", "--out", "x.png", *extra])
    tree, sim = cli.make_simulation(args)
    assert sim.model == model
    assert sim.wind.model == ("paper" if extra else "physical")
    args = cli.build_parser().parse_args(["trace", "beam", "--pull", "1,0,0", "--out", "t.csv", *extra])
    assert options.model(args) == model
