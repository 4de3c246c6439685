"""What every ``kcplan`` subcommand shares: one-line input errors and argument types."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

__all__ = [
    "InputError",
    "Parser",
    "duration",
    "finite_float",
    "load_input",
    "non_negative_float",
    "output_file",
    "planner_name",
    "positive_float",
    "positive_int",
]


class InputError(Exception):
    """Bad user input; reported as one line with exit code 2."""


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one :class:`InputError` line, no usage dump."""

    def error(self, message: str) -> None:
        raise InputError(f"{self.prog}: {message}")


def output_file(path: str | None, option: str, suffixes: tuple[str, ...] = ()) -> None:
    """Refuse an output file before any work: its folder must exist (no lost plan)."""
    if path is None:
        return
    out = Path(path)
    if suffixes and out.suffix.lower() not in suffixes:
        raise InputError(
            f"{out}: {option}: expected a {' or '.join(suffixes)} file name, got {out.name!r}"
        )
    if not out.parent.is_dir():
        raise InputError(
            f"{out}: {option}: expected a file in an existing folder, got {out.parent}"
        )
    if out.is_dir():
        raise InputError(f"{out}: {option}: expected a file name, got a folder")


def load_input(path: str, check: bool = True):
    """Load a scenario, turning every problem with it into an :class:`InputError`."""
    from kcplan.scenarios import load_scenario
    from kcplan.world import ScenarioError

    try:
        return load_scenario(path, check=check)
    except ScenarioError as err:
        raise InputError(str(err)) from None


def positive_float(text: str) -> float:
    value = finite_float(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return value


def non_negative_float(text: str) -> float:
    value = finite_float(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a number >= 0, got {text!r}")
    return value


def positive_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def finite_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not np.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def planner_name(text: str) -> str:
    """A planner name (``--planner``); refused planners get their reason."""
    from kcplan.planning.names import check_planner_name

    try:
        return check_planner_name(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def duration(seconds: float) -> str:
    """A time in a unit that shows it: ``"3.20 s"``, ``"12.3 ms"``, ``"85 us"``."""
    if seconds >= 1.0:
        return f"{seconds:.2f} s"
    if seconds >= 1e-3:
        return f"{seconds * 1e3:.3g} ms"
    return f"{seconds * 1e6:.3g} us"
