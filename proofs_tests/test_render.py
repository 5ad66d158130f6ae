"""``langur render`` (issue 12, §10.1 Fig. 13): a program over a grid of two parameters.

The arrays it writes are the batch API's (same seed, same numbers); the derivative image has the
boundary line where the scene's line x + y + c = 0 crosses the pixels, and standard AD has none;
bad grids are usage errors; nothing is written over a program."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np
import pytest
from paths import EXAMPLES, REPO

from langur.cli import main
from langur.frontend import load
from langur.operational.batch import estimate_batch

SCENE = str(EXAMPLES / "scene.lgr")
GRID = "px=0:0.9:10,py=0:0.9:10"


def test_render_arrays_are_the_batch_api_and_show_the_line(tmp_path, capsys):
    npz = tmp_path / "scene.npz"
    status = main(["render", SCENE, "--grid", GRID, "--at", "h=0.1", "--wrt", "c", "--exact",
                   "--samples", "100", "--seed", "5", "--npz", str(npz), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert status == 0
    assert out["exact"]["value_beyond_5se"] == 0 and out["exact"]["derivative_beyond_5se"] == 0
    assert out["written"] == [str(npz)]
    a = np.load(npz)
    assert a["value"].shape == (10, 10) and np.array_equal(a["px"], np.linspace(0, 0.9, 10))
    # the same numbers as the batch API: rows are py, columns px
    loaded = load(SCENE)
    px, py = np.meshgrid(np.linspace(0, 0.9, 10), np.linspace(0, 0.9, 10))
    b = estimate_batch(loaded, {"px": px.ravel(), "py": py.ravel(), "h": 0.1}, direction={"c": 1.0},
                       samples=100, seed=5)
    assert np.array_equal(a["value"], b.value.reshape(10, 10))
    assert np.array_equal(a["derivative"], b.derivative.reshape(10, 10))
    # the line x + y = 1.003 crosses pixel (i, j) iff px + py ≤ 1.003 ≤ px + py + 0.2: the boundary
    # image is nonzero exactly there; standard AD (the constant shader: no interior) is 0 everywhere
    crossed = (px + py <= 1.003) & (px + py + 0.2 >= 1.003)
    assert np.all(a["boundary"][crossed] > 0) and np.all(a["boundary"][~crossed] == 0)
    assert np.all(a["standard_ad"] == 0)
    assert np.allclose(a["exact_derivative"][~crossed], 0)


@pytest.mark.parametrize("grid,message", [
    ("px=0:1:10", "two different parameters"),
    ("px=0:1:10,px=0:1:10", "two different parameters"),
    ("px=0:1:10,q=0:1:10", "no such parameter"),
    ("px=0:1:0,py=0:1:10", "between 1 and"),
    ("px=0:1:10,py=0:nan:10", "finite"),
    ("px=0:1,py=0:1:10", "NAME=START:STOP:N"),
    ("px=0:1:2000,py=0:1:2000", "samples in all"),
])
def test_bad_grids_are_usage_errors(grid, message, capsys):
    assert main(["render", SCENE, "--grid", grid]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


def test_render_never_writes_over_a_program(tmp_path, capsys):
    prog = tmp_path / "p.lgr"
    prog.write_text("param a = 0.5, b = 0.5\nint ([0, 1]) [x <= a] * b d(x)\n")
    for flag in ("-o", "--npz"):
        assert main(["render", str(prog), "--grid", "a=0:1:3,b=0:1:3", flag, str(prog)]) == 2
        assert "over a program" in capsys.readouterr().err
    assert prog.read_text().startswith("param a")


def test_render_draws_the_images(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "scene.png"
    r = subprocess.run([sys.executable, "-m", "langur", "render", SCENE, "--grid", GRID, "--at", "h=0.1",
                        "--wrt", "c", "--exact", "-o", str(out)], capture_output=True, text=True, cwd=REPO,
                       timeout=300)
    assert r.returncode == 0, r.stderr
    assert os.path.getsize(out) > 20_000 and "Traceback" not in r.stderr
    import matplotlib.image as mpimg

    img = mpimg.imread(out)
    assert img.shape[0] > 400 and img.shape[1] > 1000  # two rows of panels, three columns
