"""The repository stands on its own (issue "Stand on its own"): packaging, license, entry points.

* every Python package of the project is listed in ``pyproject.toml`` (the list is written by hand
  because ``examples/`` is installed as ``langur.examples``), and the example programs go with it;
* nothing in the repository reaches for a folder beside it or an environment variable to find
  its own files;
* ``python -m langur`` is the ``langur`` command; the license file matches the metadata.
"""

import subprocess
import sys
import tomllib

from paths import REPO

PYPROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())


def test_every_package_is_listed():
    listed = set(PYPROJECT["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(REPO).parts) for top in ("langur", "viz")
             for p in (REPO / top).rglob("__init__.py")}
    assert found <= listed, f"packages missing from pyproject.toml: {sorted(found - listed)}"
    assert PYPROJECT["tool"]["setuptools"]["package-dir"]["langur.examples"] == "examples"
    assert "langur.examples" in listed


def test_examples_are_found_by_reproduce():
    from langur.reproduce import examples_dir

    d = examples_dir()
    assert (d / "fig1.lgr").is_file() and (d / "degenerate" / "coincident.lgr").is_file()


def test_nothing_reaches_outside_the_repository():
    tracked = subprocess.run(["git", "-C", str(REPO), "ls-files"], capture_output=True, text=True).stdout.split()
    if not tracked:  # not a git checkout: look at the Python files
        tracked = [str(p.relative_to(REPO)) for p in REPO.rglob("*.py")]
    bad = []
    for name in tracked:
        path = REPO / name
        if path.suffix not in {".py", ".toml", ".lgr", ".cfg", ".yaml"} and name != ".ci/run":
            continue
        text = path.read_text(errors="replace")
        for needle in ("../" + "shared", "LANGUR_" + "SHARED", "LANGUR_" + "EXAMPLES"):
            if needle in text and name != "proofs_tests/test_packaging.py":
                bad.append(f"{name}: {needle}")
    assert bad == []


def test_python_dash_m_langur_is_the_command():
    r = subprocess.run([sys.executable, "-m", "langur", "--help"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "reproduce" in r.stdout


def test_license_matches_metadata():
    assert PYPROJECT["project"]["license"] == "MIT" and PYPROJECT["project"]["license-files"] == ["LICENSE"]
    assert (REPO / "LICENSE").read_text().startswith("MIT License")
