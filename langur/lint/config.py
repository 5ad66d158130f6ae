"""``[tool.langur]`` configuration of ``langur check`` (CLI.md, Diagnostics).

Read from the nearest ``pyproject.toml`` above the checked file that has a ``[tool.langur]``
table (as ruff does with ``[tool.ruff]``); none found: everything is selected.  Keys::

    [tool.langur]
    select = ["X3"]                 # code prefixes to report ("ALL" = everything); default all
    ignore = ["X303", "X302"]       # code prefixes never to report
    per-file-ignores = {"degenerate/*.lgr" = ["X301"]}   # glob (relative to the pyproject's
                                                         # directory) → code prefixes

Prefix semantics as in ruff: ``X3`` matches every ``X3xx`` code, ``X30`` every ``X30x``.  A code
is reported when it matches ``select`` and no ``ignore`` (nor a matching ``per-file-ignores``
entry); ``--select`` on the command line replaces ``select``, ``--ignore`` adds to ``ignore``.
Front-end errors (``E1xx`` syntax, ``T2xx`` typing) are always reported: a program that does not
parse or type has no meaning to lint (like ruff's syntax errors).
"""

from __future__ import annotations

import fnmatch
import os
import tomllib
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path, PurePosixPath


class ConfigError(Exception):
    """A malformed ``[tool.langur]`` table (the CLI reports it as a usage error, status 2)."""


@dataclass(frozen=True)
class Config:
    select: tuple[str, ...] | None = None  # None: everything
    ignore: tuple[str, ...] = ()
    per_file_ignores: tuple[tuple[str, tuple[str, ...]], ...] = ()
    root: Path | None = None  # the directory of the pyproject.toml it came from
    source: Path | None = None
    extra: dict = field(default_factory=dict, compare=False)

    def with_cli(self, select: list[str] | None, ignore: list[str] | None) -> Config:
        return Config(
            tuple(select) if select else self.select,
            self.ignore + tuple(ignore or ()),
            self.per_file_ignores,
            self.root,
            self.source,
        )

    def unknown_prefixes(self, known: frozenset[str]) -> list[tuple[str, str]]:
        """``(where, prefix)`` for each prefix that matches no code in ``known`` (a typo would
        otherwise select nothing, or ignore nothing, without a word)."""
        where = f"{self.source}: [tool.langur] " if self.source is not None else ""
        entries = [("select", p) for p in self.select or ()] + [("ignore", p) for p in self.ignore]
        entries += [(f"per-file-ignores[{glob!r}]", p) for glob, codes in self.per_file_ignores for p in codes]
        return [(where + key, p) for key, p in entries if not any(_matches(c, p) for c in known)]

    def enabled(self, code: str, path: str | None) -> bool:
        """Is ``code`` reported for a finding in the checked file ``path``?"""
        if code[:1] in ("E", "T"):
            return True
        if self.select is not None and not any(_matches(code, p) for p in self.select):
            return False
        if any(_matches(code, p) for p in self.ignore):
            return False
        if path is not None and self.per_file_ignores:
            for pattern, codes in self.per_file_ignores:
                if _path_matches(path, pattern, self.root) and any(_matches(code, p) for p in codes):
                    return False
        return True


def _matches(code: str, prefix: str) -> bool:
    return prefix.upper() == "ALL" or code.upper().startswith(prefix.upper())


def _path_matches(path: str, pattern: str, root: Path | None) -> bool:
    p = Path(path)
    candidates = [PurePosixPath(p.as_posix())]
    if root is not None:
        try:
            candidates.append(PurePosixPath(Path(os.path.abspath(p)).relative_to(root).as_posix()))
        except ValueError:
            pass
    for c in candidates:
        text = str(c)
        if fnmatch.fnmatchcase(text, pattern) or fnmatch.fnmatchcase(text, pattern.lstrip("./")):
            return True
        if "/" not in pattern and fnmatch.fnmatchcase(c.name, pattern):
            return True
    return False


def _codes(value, what: str, source: Path) -> tuple[str, ...]:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not all(isinstance(v, str) and v.strip() for v in value):
        raise ConfigError(f"{source}: [tool.langur] {what} must be a list of code prefixes (strings)")
    return tuple(v.strip() for v in value)


_KNOWN = {"select", "ignore", "per-file-ignores"}


def _read(pyproject: Path) -> Config | None:
    try:
        raw = pyproject.read_bytes()
    except OSError:
        return None
    return _parse(pyproject, raw)


@lru_cache(maxsize=64)
def _parse(pyproject: Path, raw: bytes) -> Config | None:
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise ConfigError(f"{pyproject}: not valid TOML: {e}") from None
    table = data.get("tool", {}).get("langur") if isinstance(data.get("tool"), dict) else None
    if table is None:
        return None
    if not isinstance(table, dict):
        raise ConfigError(f"{pyproject}: [tool.langur] must be a table")
    unknown = sorted(set(table) - _KNOWN)
    if unknown:
        raise ConfigError(
            f"{pyproject}: [tool.langur] has unknown key(s) {', '.join(unknown)} "
            f"(known: {', '.join(sorted(_KNOWN))})"
        )
    select = _codes(table["select"], "select", pyproject) if "select" in table else None
    ignore = _codes(table.get("ignore", []), "ignore", pyproject)
    pfi = table.get("per-file-ignores", {})
    if not isinstance(pfi, dict):
        raise ConfigError(f"{pyproject}: [tool.langur] per-file-ignores must be a table of glob = [codes]")
    per_file = tuple((str(k), _codes(v, f"per-file-ignores[{k!r}]", pyproject)) for k, v in pfi.items())
    return Config(select, ignore, per_file, pyproject.parent.resolve(), pyproject)


def find_config(start: str | os.PathLike) -> Config:
    """The configuration for a file at ``start`` (or a directory): the nearest ``pyproject.toml``
    with a ``[tool.langur]`` table in it or above it; defaults when there is none."""
    here = Path(os.path.abspath(start))
    if not here.is_dir():
        here = here.parent
    for d in (here, *here.parents):
        candidate = d / "pyproject.toml"
        if candidate.is_file():
            cfg = _read(candidate)
            if cfg is not None:
                return cfg
    return Config()
