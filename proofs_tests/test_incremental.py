"""Incremental loading (issue 15): a module is elaborated once per content and imported signatures.

Each test compares the cached load with a load from an empty cache (the same program, the same
parameters), and counts what was elaborated (``frontend.load_stats``)."""

import pytest

from langur import frontend
from langur.diagnostics import LangurError

SCENE = ("from shader import shade\nparam c = -1\n"
         "int ([0, 1], [0, 1]) [x + y + c >= 0] * shade(x, y, c) d(x, y)\n")
SHADER_A = "def shade(x: var, y: var, c: param) = 1\n"
SHADER_B = "def helper(x: var) = x * x\ndef shade(x: var, y: var, c: param) = helper(x) + y\n"
SHADER_C = "def shade(x: var, y: var, c: param, d: param) = d\n"  # another signature


@pytest.fixture(autouse=True)
def _fresh():
    frontend.clear_load_cache()
    yield
    frontend.clear_load_cache()


def _fresh_load(path, modules=None):
    frontend.clear_load_cache()
    out = frontend.load(str(path), modules)
    frontend.clear_load_cache()
    return out


def _write(tmp_path, **files):
    for name, text in files.items():
        (tmp_path / f"{name}.lgr").write_text(text)


def test_reloading_elaborates_nothing(tmp_path):
    _write(tmp_path, scene=SCENE, shader=SHADER_A)
    first = frontend.load(str(tmp_path / "scene.lgr"))
    assert frontend.load_stats()["elaborated"] == ["shader", "scene"]
    frontend.reset_load_stats()
    again = frontend.load(str(tmp_path / "scene.lgr"))
    assert frontend.load_stats() == {"elaborated": [], "reused": 2, "modules": 2}
    assert again.program == first.program and list(again.modules) == list(first.modules)


def test_a_swap_elaborates_the_new_shader_only(tmp_path):
    _write(tmp_path, scene=SCENE, shader=SHADER_A, other=SHADER_B)
    frontend.load(str(tmp_path / "scene.lgr"))
    frontend.reset_load_stats()
    swapped = frontend.load(str(tmp_path / "scene.lgr"), {"shader": str(tmp_path / "other.lgr")})
    assert frontend.load_stats()["elaborated"] == ["shader"]
    reference = _fresh_load(tmp_path / "scene.lgr", {"shader": str(tmp_path / "other.lgr")})
    assert swapped.program == reference.program and swapped.params == reference.params
    assert swapped.modules["shader"].defs == reference.modules["shader"].defs


def test_an_edited_signature_invalidates_the_dependents(tmp_path):
    _write(tmp_path, scene=SCENE, shader=SHADER_A)
    frontend.load(str(tmp_path / "scene.lgr"))
    _write(tmp_path, shader=SHADER_C)  # shade takes one more param: the scene's call is now wrong
    frontend.reset_load_stats()
    with pytest.raises(LangurError) as cached:
        frontend.load(str(tmp_path / "scene.lgr"))
    assert "scene" in frontend.load_stats()["elaborated"]
    frontend.clear_load_cache()
    with pytest.raises(LangurError) as fresh:
        frontend.load(str(tmp_path / "scene.lgr"))
    assert [d.format() for d in cached.value.diagnostics] == [d.format() for d in fresh.value.diagnostics]


def test_an_edited_body_is_seen_by_the_program(tmp_path):
    _write(tmp_path, scene=SCENE, shader=SHADER_A)
    before = frontend.load(str(tmp_path / "scene.lgr"))
    _write(tmp_path, shader=SHADER_B)  # same signature, another body
    frontend.reset_load_stats()
    after = frontend.load(str(tmp_path / "scene.lgr"))
    assert frontend.load_stats()["elaborated"] == ["shader"]
    assert after.program != before.program
    assert after.program == _fresh_load(tmp_path / "scene.lgr").program


def test_errors_are_reported_on_every_load(tmp_path):
    _write(tmp_path, scene=SCENE.replace("shade(x, y, c)", "shade(x, c)"), shader=SHADER_A)
    said = []
    for _ in range(2):
        with pytest.raises(LangurError) as e:
            frontend.load(str(tmp_path / "scene.lgr"))
        said.append([d.format() for d in e.value.diagnostics])
    assert said[0] == said[1] and said[0]
