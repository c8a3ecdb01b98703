"""Malformed presets are refused with one clear line naming the file, the key and what was expected."""

import subprocess
import sys
from pathlib import Path

import pytest

import treeanim as ta
from treeanim import PresetError

GOOD = Path(ta.load_preset("small_cherry").source).read_text()


def write(tmp_path, text, name="bad.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


# (what is wrong, how to break the good file, the key the message must name, words it must contain)
CASES = [
    ("not TOML", lambda s: s.replace("[trunk]", "[trunk"), None, "not valid TOML"),
    ("missing key", lambda s: s.replace('type = "tree"\n', ""), "type", "missing"),
    ("missing trunk length", lambda s: s.replace("[trunk]\nlength = 0.8\n", "[trunk]\n"), "trunk.length", "missing"),
    ("wrong type", lambda s: s.replace("segments = 2", 'segments = "two"', 1), "trunk.segments", "integer"),
    ("negative count", lambda s: s.replace("count = 816", "count = -816"), "leaves.count", "[0,"),
    ("NaN", lambda s: s.replace("diameter = 0.14", "diameter = nan"), "trunk.diameter", "number"),
    ("angle out of range", lambda s: s.replace("down_angle = 36.0", "down_angle = 400.0"), "levels[0].down_angle", "180"),
    ("unknown key", lambda s: s.replace("taper = 0.25", "tapr = 0.25"), "trunk.tapr", "unknown key"),
    ("bad range", lambda s: s.replace("f = [0.5, 1.0]", "f = [1.0, 0.5]"), "physics.summer.branch.f", "min <= max"),
    ("zero frequency", lambda s: s.replace("f = [0.5, 1.0]", "f = [0.0, 1.0]"), "physics.summer.branch.f", "number"),
    ("winter above summer", lambda s: s.replace("winter_count = 52", "winter_count = 900"), "leaves.winter_count", "at most"),
    ("outline on the left", lambda s: s.replace("[0.24, 0.30], [0.24, 0.46]", "[0.24, 0.30], [-0.1, 0.4], [0.24, 0.46]"),
     "lamina.outline", "x >= 0"),
    ("leaf level missing", lambda s: s.replace("levels = [3, 4, 5, 6]", "levels = [9]"), "leaves.levels", "between"),
    ("blades turned too far", lambda s: s.replace("turn_var = 55.0", "turn_var = 120.0"), "leaves.turn_var", "[0, 90]"),
    ("leader past the trunk", lambda s: s.replace("turn_var = 55.0", "turn_var = 55.0\nleader = 1.5"), "leaves.leader",
     "[0, 1]"),
    ("physics scalar", lambda s: s.replace("[physics.summer]", "[physics]\nei_max = -3\n[physics.summer]"),
     "physics.ei_max", "(0, 1e+12]"),
    ("bark colour", lambda s: s.replace("color = [0.38, 0.25, 0.22]", "color = [0.38, 0.25]"), "bark.color", "[r, g, b]"),
    ("bark furrows", lambda s: s.replace("furrows = 8.0", "furrows = 0.0"), "bark.furrows", "[1, 64]"),
    # accepted once, and the simulation went NaN (issue #14, item 5)
    ("huge damping scale", lambda s: s.replace("[physics.summer]", "[physics]\nleaf_zeta_w_scale = 1e300\n[physics.summer]"),
     "physics.leaf_zeta_w_scale", "[0, 100]"),
    ("huge wind gain", lambda s: s.replace("[physics.summer]", "[physics]\nwind_gain_leaf = 1e308\n[physics.summer]"),
     "physics.wind_gain_leaf", "[0, 1000]"),
]


@pytest.mark.parametrize("what,mutate,key,words", CASES, ids=[c[0] for c in CASES])
def test_bad_preset_api(tmp_path, what, mutate, key, words):
    text = mutate(GOOD)
    assert text != GOOD, "the mutation must change the file"
    path = write(tmp_path, text)
    with pytest.raises(PresetError) as err:
        ta.load_tree(path)
    msg = str(err.value)
    assert isinstance(err.value, ValueError)
    assert "\n" not in msg
    assert str(path) in msg
    if key:
        assert f"'{key}'" in msg
    assert words in msg


def test_crossing_outline_is_refused(tmp_path):
    text = GOOD.replace("[0.24, 0.30], [0.24, 0.46]", "[0.24, 0.30], [0.05, 0.7], [0.05, 0.4], [0.3, 0.55]")
    assert text != GOOD
    with pytest.raises(PresetError, match="'lamina.outline': the 'ovate serrated' outline crosses itself"):
        ta.load_tree(write(tmp_path, text))


def test_unknown_preset_lists_known():
    with pytest.raises(PresetError) as err:
        ta.load_preset("oak")
    for name in ta.list_presets():
        assert name in str(err.value)


def test_missing_file():
    with pytest.raises(PresetError, match="cannot read"):
        ta.load_tree("/nonexistent/tree.toml")


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "treeanim", *args], capture_output=True, text=True, timeout=120)


def test_cli_bad_preset_exit_2_no_traceback(tmp_path):
    path = write(tmp_path, GOOD.replace("count = 816", "count = -816"))
    res = run_cli("info", str(path))
    assert res.returncode == 2
    assert "Traceback" not in res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "leaves.count" in lines[0] and str(path) in lines[0]


def test_cli_unknown_preset(tmp_path):
    res = run_cli("info", "oak")
    assert res.returncode == 2 and "Traceback" not in res.stderr and "small_cherry" in res.stderr


def test_cli_info_of_a_tree_the_paper_has_not_shows_no_paper_totals():
    res = run_cli("info", "beam")
    total = next(line for line in res.stdout.splitlines() if line.startswith("total"))
    assert res.returncode == 0 and total.count("—") == 2 and " 0" not in total, total


def test_cli_info_prints_our_counts_beside_the_paper():
    res = run_cli("info", "large_cherry", "--season", "1")
    assert res.returncode == 0, res.stderr
    ours = ta.load_preset("large_cherry").stats(1.0)
    leaf_row = next(line for line in res.stdout.splitlines() if line.startswith("leaf"))
    assert f"{ours['leaves']:,} /" in leaf_row and f"{ours['leaf_nodes']:,} /" in leaf_row
    assert f"{ours['leaf_triangles']:,} /" in leaf_row
    assert "48,504" in leaf_row  # the paper's winter leaf triangles, beside ours


def test_missing_modes_for_a_kind_the_tree_has(tmp_path):
    text = GOOD.replace('leaf = { f = [1.2, 1.8], zeta = [0.08, 0.12] }\n', "", 1)
    assert text != GOOD
    with pytest.raises(PresetError, match="'physics.summer.leaf': missing; the tree has leaves"):
        ta.load_tree(write(tmp_path, text))


def test_empty_grass_refused(tmp_path):
    grass = Path(ta.load_preset("grassland").source).read_text().replace("count = 5000", "count = 0")
    with pytest.raises(PresetError, match="'grass.count': expected at least 1 blade"):
        ta.load_tree(write(tmp_path, grass))


@pytest.mark.parametrize("args,words", [
    (["export", "beam", "--seconds", "1e308", "--out", "a.glb"], "--seconds"),
    (["export", "beam", "--seconds", "100000", "--fps", "100000", "--out", "a.glb"], "at most"),
    (["export", "beam", "--turbulence", "5", "--out", "a.glb"], "--turbulence"),
    (["export", "beam", "--turbulence", "1.5", "--out", "a.glb"], "turbulence"),
    (["export", "beam", "--wind-preset", "hurricane", "--out", "a.glb"], "--wind-preset"),
    (["export", "beam", "--seed", "-1", "--out", "a.glb"], "--seed"),
    (["render", "beam", "--start", "1e5", "--seconds", "100", "--out", "a.mp4"], "at most"),
    (["trace", "beam", "--pull", "1,0,0", "--hold", "1e308", "--out", "a.csv"], "--hold"),
    (["bench", "--wind", "5000"], "--wind"),
    (["trace", "beam", "--pull", "1,0,0", "--rate", "0.01", "--seconds", "1", "--out", "a.csv"], "at least 2 samples"),
    (["view", "beam", "--size", "0x3"], "at least 1 pixel"),
    (["bogus"], "invalid choice"),
])
def test_cli_out_of_range_one_line(tmp_path, args, words):
    res = subprocess.run([sys.executable, "-m", "treeanim", *args], capture_output=True, text=True, cwd=tmp_path,
                         timeout=120)
    assert res.returncode == 2
    assert "Traceback" not in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1 and words in res.stderr
    assert not list(tmp_path.iterdir())


# ------------------------------------------------------------------ files that never end
def load_in_time(path, seconds=10.0):
    """load_tree(path) in a thread: the PresetError it raised, failing if it blocks."""
    import threading

    result = {}

    def run():
        try:
            ta.load_tree(path)
        except PresetError as e:
            result["error"] = e

    th = threading.Thread(target=run, daemon=True)
    th.start()
    th.join(seconds)
    assert not th.is_alive(), f"loading {path} blocked"
    assert "error" in result, f"{path} was accepted"
    msg = str(result["error"])
    assert "\n" not in msg and str(path) in msg
    return msg


@pytest.mark.parametrize("target", ["/dev/zero", "/dev/urandom"])
def test_a_preset_path_to_an_endless_device_is_refused_unread(tmp_path, target):
    link = tmp_path / "endless.toml"
    link.symlink_to(target)
    assert "not a regular file" in load_in_time(link)


def test_a_fifo_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "pipe.toml"
    import os

    os.mkfifo(fifo)
    assert "not a regular file" in load_in_time(fifo)


def test_a_huge_preset_file_is_refused_unread(tmp_path):
    path = tmp_path / "huge.toml"
    with open(path, "wb") as f:
        f.truncate(3 << 30)  # 3 GB, sparse: reading it would take the memory
    assert "bytes; a preset file may have at most 1,048,576" in load_in_time(path)


@pytest.mark.parametrize("nested", ["x = " + "[" * 1000 + "]" * 1000,
                                    "x = " + "{a = " * 1000 + "1" + "}" * 1000,
                                    "x = " + "[" * 200 + "]" * 200])
def test_deeply_nested_values_are_refused_in_one_line(tmp_path, nested):
    path = write(tmp_path, nested + "\n" + GOOD)
    msg = load_in_time(path)
    assert "nested too deeply" in msg or "'x'" in msg


def test_cli_refuses_a_device_in_one_line(tmp_path):
    link = tmp_path / "zero.toml"
    link.symlink_to("/dev/zero")
    r = subprocess.run([sys.executable, "-m", "treeanim", "info", str(link)], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 2
    assert r.stderr.strip().count("\n") == 0 and "not a regular file" in r.stderr and "Traceback" not in r.stderr


def test_cli_output_cut_short_by_its_reader_stops_quietly():
    """`treeanim info small_cherry | head -c 10` where the reader has gone before the table is
    written: no BrokenPipeError traceback, exit 141 (the shell's code for a closed pipe)."""
    import os

    r, w = os.pipe()
    os.close(r)  # the reader is gone before anything is written
    try:
        p = subprocess.run([sys.executable, "-m", "treeanim", "info", "small_cherry"], stdout=w,
                           stderr=subprocess.PIPE, timeout=60)
    finally:
        os.close(w)
    assert p.returncode == 141, p.stderr.decode()
    assert p.stderr == b""


# --------------------------------------------------------------------------- issue #14, items 2 and 11
@pytest.mark.parametrize("what,mutate,key,words", [
    ("two levels of 100,000", lambda s: s.replace("count = 3\n", "count = 100000\n", 1).replace("count = 2\n", "count = 100000\n", 1),
     "levels[].count", "a preset may build at most"),
    ("50,000 outline points", lambda s: s.replace("outline = [[0.0, 0.0],", "outline = [[0.0, 0.0], " + "[0.1, 0.5], " * 50_000),
     "lamina.outline", "3 to 1000"),
    ("a 100 KB name", lambda s: s.replace('name = "small_cherry"', 'name = "' + "x" * 100_000 + '"'), "name", "at most 1000"),
])
def test_presets_that_ask_for_too_much_are_refused_at_once(tmp_path, monkeypatch, what, mutate, key, words):
    """Each key in bounds, together billions of objects (or a huge outline): refused from the
    counts, before anything is built (the generator is never called), in one short line."""
    from treeanim.model import presets

    generated = []
    monkeypatch.setattr(presets, "generate", lambda spec: generated.append(spec))
    path = write(tmp_path, mutate(GOOD))
    with pytest.raises(PresetError) as err:
        ta.load_tree(path)
    msg = str(err.value)
    assert generated == [], "refused only after building"
    assert f"'{key}" in msg and words in msg and len(msg) < 300 + len(str(path)), msg[:300]


def test_grass_of_100000_blades_of_64_segments_is_refused(tmp_path):
    text = Path(ta.load_preset("grassland").source).read_text()
    text = text.replace("count = 5000", "count = 100000").replace("segments = 3", "segments = 64")
    with pytest.raises(PresetError, match="grass.count, grass.segments.*a preset may build at most"):
        ta.load_tree(write(tmp_path, text))


@pytest.mark.parametrize("key", ["size_var", "down_var"])
def test_a_negative_zero_is_zero(tmp_path, key):
    import re

    text, n = re.subn(rf"^{key} = .*$", f"{key} = -0.0", GOOD, count=1, flags=re.M)
    assert n == 1
    ta.load_tree(write(tmp_path, text))  # once: "scale < 0" from the random generator, with no key


def test_an_integer_of_thousands_of_digits_is_one_short_line(tmp_path):
    with pytest.raises(PresetError, match="not valid TOML") as err:
        ta.load_tree(write(tmp_path, GOOD.replace("length = 0.8", "length = " + "1" * 5000, 1)))
    assert len(str(err.value)) < 300
