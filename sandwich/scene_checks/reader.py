"""Reading values out of nested TOML tables while collecting every problem (:class:`Reader`).

Each check names the key in dotted form (``debonds[2].end``) and says why it is refused.
"""

from __future__ import annotations

import difflib
import re
from typing import Any

from sandwich.scene import (
    NAME_PATTERN,
    Problem,
    is_finite_number,
)

__all__ = ["MAX_MAGNITUDE", "Reader", "check_name", "join_key", "typename"]

MAX_MAGNITUDE = 1e12  # any number of a scene (N, mm, MPa): beyond it sizes overflow the meshers


_MISSING = object()


class Reader:
    """Collects problems while reading values out of nested TOML tables."""

    def __init__(self, fname: str):
        self.fname = fname
        self.problems: list[Problem] = []

    def fail(self, key: str, reason: str) -> None:
        """Record a problem at ``key``."""
        self.problems.append(Problem(self.fname, key, reason))

    def table(self, value: Any, key: str, allowed: tuple[str, ...],
              required: tuple[str, ...] = (),
              renamed: dict[str, str] | None = None) -> dict[str, Any] | None:
        """Check that ``value`` is a table with only ``allowed`` keys and all ``required`` ones.

        ``renamed`` maps a key's former name to its name now: the old one is refused with it.
        """
        if not isinstance(value, dict):
            self.fail(key, f"expected a table, got {typename(value)}")
            return None
        for k in value:
            if renamed and k in renamed:
                self.fail(join_key(key, k), f"renamed '{renamed[k]}'")
            elif k not in allowed:
                near = difflib.get_close_matches(k, allowed, n=1, cutoff=0.6)
                hint = (f" (did you mean '{near[0]}'?)" if near
                        else f" (allowed: {', '.join(allowed)})")
                self.fail(join_key(key, k), f"unknown key{hint}")
        for k in required:
            if k not in value:
                self.fail(join_key(key, k), "missing required key")
        return value

    def number(self, tbl: dict[str, Any], k: str, key: str, *, default: Any = _MISSING,
               positive: bool = False, nonneg: bool = False, nonzero: bool = False) -> Any:
        """Read a finite number (int or float), with optional sign checks."""
        if k not in tbl:
            return None if default is _MISSING else default
        v = tbl[k]
        full = join_key(key, k)
        if not is_finite_number(v):
            self.fail(full, "expected a finite number" if isinstance(v, float)
                      else f"expected a number, got {typename(v)}")
            return None
        v = float(v)
        if abs(v) > MAX_MAGNITUDE:
            self.fail(full, f"{v:g} is beyond any physical scale of this tool (|value| <= "
                      f"{MAX_MAGNITUDE:g} in N, mm, MPa)")
            return None
        if positive and v <= 0:
            self.fail(full, f"must be positive, got {v:g}")
            return None
        if nonneg and v < 0:
            self.fail(full, f"must not be negative, got {v:g}")
            return None
        if nonzero and v == 0:
            self.fail(full, "must not be zero")
            return None
        return v

    def integer(self, tbl: dict[str, Any], k: str, key: str, *, default: Any = _MISSING,
                lo: int | None = None, hi: int | None = None) -> Any:
        """Read an integer within [lo, hi]."""
        if k not in tbl:
            return None if default is _MISSING else default
        v = tbl[k]
        full = join_key(key, k)
        if isinstance(v, bool) or not isinstance(v, int):
            self.fail(full, f"expected an integer, got {typename(v)}")
            return None
        if (lo is not None and v < lo) or (hi is not None and v > hi):
            self.fail(full, f"must be between {lo} and {hi}, got {v}")
            return None
        return v

    def boolean(self, tbl: dict[str, Any], k: str, key: str, *, default: bool) -> bool:
        """Read true or false."""
        v = tbl.get(k, default)
        if not isinstance(v, bool):
            self.fail(join_key(key, k), f"expected true or false, got {typename(v)}")
            return default
        return v

    def choice(self, tbl: dict[str, Any], k: str, key: str, options: tuple[str, ...], *,
               default: Any = _MISSING) -> Any:
        """Read a string that must be one of ``options``."""
        if k not in tbl:
            return None if default is _MISSING else default
        v = tbl[k]
        full = join_key(key, k)
        if not isinstance(v, str):
            self.fail(full, f"expected one of {', '.join(options)}, got {typename(v)}")
            return None
        if v not in options:
            near = difflib.get_close_matches(v, options, n=1, cutoff=0.5)
            hint = f" (did you mean '{near[0]}'?)" if near else ""
            self.fail(full, f"'{v}' is not one of {', '.join(options)}{hint}")
            return None
        return v

    def string(self, tbl: dict[str, Any], k: str, key: str, *, default: Any = _MISSING) -> Any:
        """Read a non-empty string."""
        if k not in tbl:
            return None if default is _MISSING else default
        v = tbl[k]
        if not isinstance(v, str) or not v.strip():
            self.fail(join_key(key, k), f"expected a non-empty string, got {typename(v)}")
            return None
        return v

    def array_of_tables(self, value: Any, key: str) -> list[Any]:
        """Check that ``value`` is an array of tables (``[[key]]``)."""
        if not isinstance(value, list) or not all(isinstance(x, dict) for x in value):
            self.fail(key, f"expected an array of tables ([[{key}]]), got {typename(value)}")
            return []
        return value


def join_key(key: str, k: str) -> str:
    """The dotted key of ``k`` in the table at ``key`` (``k`` alone at the top level)."""
    return f"{key}.{k}" if key else k


def typename(v: Any) -> str:
    """The TOML name of ``v``'s type, for the messages."""
    return {bool: "boolean", int: "integer", float: "number", str: "string", list: "array",
            dict: "table"}.get(type(v), type(v).__name__)


def check_name(r: Reader, name: Any, key: str) -> bool:
    """Refuse a name that cannot be a folder or file name (it becomes one in the results)."""
    if isinstance(name, str) and name and not re.fullmatch(NAME_PATTERN, name):
        r.fail(key, f"'{name[:40]}' cannot name a result folder or file: use 1-100 letters, "
               "digits, '.', '_' or '-', starting with a letter or digit")
        return False
    return True
