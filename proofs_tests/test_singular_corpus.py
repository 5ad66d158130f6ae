"""53 singular integrands (``singular_corpus.py``) fed to the analysis and to every command.

* In process: the structural analysis (``langur.lint.singular``) says "does not exist" exactly
  for the non-integrable ones, "exists" for the controls (or honestly "undecided" where marked).
* In subprocesses (one per command, each running the whole corpus through ``langur.cli.main``,
  so a signal would kill it and name the program it was on): no signal, no traceback, exit
  0/1/2, no finite exact value for a non-integrable program (``check`` reports X311/X313 and exits
  1; ``eval``/``deriv`` answer "undefined", still with the Monte Carlo number; ``show`` says
  undefined), and the controls keep their hand values.
"""

import json
import math
import subprocess
import sys

import pytest
from paths import REPO
from singular_corpus import CORPUS

from langur import frontend
from langur.lint import singular
from langur.symbolic.integrability import Verdict
from langur.transversality import point_of

VERDICT = {"D": Verdict.DIVERGENT, "I": Verdict.INTEGRABLE}


def test_the_corpus_is_big_enough():
    assert len(CORPUS) >= 50 and len({name for name, *_ in CORPUS}) == len(CORPUS)
    assert sum(v == "D" for _, _, v, *_ in CORPUS) >= 25 and sum(v == "I" for _, _, v, *_ in CORPUS) >= 15


@pytest.mark.parametrize("name, text, value, deriv, hand, heavy", CORPUS, ids=[c[0] for c in CORPUS])
def test_structural_verdicts(name, text, value, deriv, hand, heavy):
    loaded = frontend.load_text(text, f"{name}.lgr")
    point = point_of(loaded.params, {})
    v = singular.value_integrability(loaded.program, point)
    assert v.note is None, v.note
    if value == "?":
        assert v.verdict is not Verdict.DIVERGENT  # it is integrable: never called divergent
    else:
        assert v.verdict is VERDICT[value], [(b.shape, b.codim, b.alpha) for b, _ in v.blowups]
    if deriv is not None and value != "D":  # without ⟦p⟧ there is no derivative (the command says so)
        (a,) = loaded.params
        d = singular.derivative_integrability(loaded.program, point, {a: 1})
        assert d.verdict is VERDICT[deriv], [(b.shape, b.codim, b.alpha, p) for b, p in d.blowups]


DRIVER = """
import contextlib, io, json, sys
from langur.cli import main
for line in sys.stdin:
    job = json.loads(line)
    print(json.dumps({"start": job["name"]}), flush=True)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = main(job["argv"])
        except SystemExit as e:
            status = e.code
    print(json.dumps({"name": job["name"], "status": status, "out": out.getvalue(), "err": err.getvalue()}),
          flush=True)
"""


def _argv(command, path, text, heavy):
    params = [ln.split()[1] for ln in text.splitlines() if ln.startswith("param ")]
    argv = [command, str(path)]
    if command in ("eval", "deriv"):
        argv += ["--samples", "200", "--json"] + (["--engine", "mc"] if heavy else [])
    if command == "deriv":
        argv += ["--no-theorem"]
    if command == "show":
        argv += ["--core"] if heavy else (["--wrt", params[0]] if params else [])
    return argv


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Every command on every program, one child process per command, all four at once."""
    d = tmp_path_factory.mktemp("corpus")
    procs = {}
    for command in ("check", "eval", "deriv", "show"):
        jobs = []
        for name, text, *_, heavy in CORPUS:
            path = d / f"{name}.lgr"
            path.write_text(text)
            jobs.append(json.dumps({"name": name, "argv": _argv(command, path, text, heavy)}))
        p = subprocess.Popen([sys.executable, "-c", DRIVER], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, cwd=REPO)
        procs[command] = (p, "\n".join(jobs) + "\n")
    results = {}
    for command, (p, jobs) in procs.items():
        out, err = p.communicate(jobs, timeout=240)
        lines = [json.loads(ln) for ln in out.splitlines() if ln.strip()]
        started = [ln["start"] for ln in lines if "start" in ln]
        assert p.returncode == 0, f"{command} died (status {p.returncode}) on {started[-1:]}: {err[-2000:]}"
        results[command] = {ln["name"]: ln for ln in lines if "name" in ln}
    return results


@pytest.mark.parametrize("name, text, value, deriv, hand, heavy", CORPUS, ids=[c[0] for c in CORPUS])
def test_every_command(runs, name, text, value, deriv, hand, heavy):
    for command in ("check", "eval", "deriv", "show"):
        r = runs[command][name]
        assert r["status"] in (0, 1, 2), (command, r)
        assert "Traceback" not in r["err"] and "internal error" not in r["err"], (command, r["err"])
    check, ev, dv, show = (runs[c][name] for c in ("check", "eval", "deriv", "show"))
    has_param = text.startswith("param")
    if value == "D":
        assert check["status"] == 1 and " error X311 " in check["out"]
        e = json.loads(ev["out"])
        assert ev["status"] == 1 and e["exact"] is None and e["undefined"]
        assert e["mc"]["finite_variance"] is False  # the Monte Carlo number is still printed, marked
        if has_param:
            d = json.loads(dv["out"])
            assert dv["status"] == 1 and d["exact"] is None and d["undefined"]
        assert show["status"] == 1 and "undefined" in show["out"]
        return
    e = json.loads(ev["out"])
    assert ev["status"] == 0 or value == "?", ev
    if not heavy and value == "I":
        assert " error X311 " not in check["out"]
        ex = e["exact"]
        assert ex is not None, ev["err"]
        if hand is not None:
            assert abs(ex["value"] - hand) <= 1e-6 * max(1.0, abs(hand)) + ex.get("error", 0.0), (ex, hand)
    if deriv == "D":
        assert check["status"] == 1 and " error X313 " in check["out"]
        d = json.loads(dv["out"])
        assert dv["status"] == 1 and d["exact"] is None and d["undefined"]
    elif deriv == "I":
        d = json.loads(dv["out"])
        assert dv["status"] == 0 and (heavy or d["exact"] is not None and math.isfinite(d["exact"]["value"]))
