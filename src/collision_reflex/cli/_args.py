"""Argument types shared by the subcommands: they turn bad text into argparse errors (exit status 2)."""

from __future__ import annotations

import argparse
import math

import numpy as np


def positive_float(text: str) -> float:
    """A finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number > 0")
    return value


def non_negative_float(text: str) -> float:
    """A finite number >= 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value) or value < 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number >= 0")
    return value


def value_range(text: str) -> np.ndarray:
    """``START:STOP:N`` (N log-spaced values, both ends included) or a comma-separated list, all > 0."""
    try:
        if ":" in text:
            start_text, stop_text, count_text = text.split(":")
            start, stop, count = positive_float(start_text), positive_float(stop_text), int(count_text)
            if count < 1:
                raise argparse.ArgumentTypeError(f"{text!r}: N must be at least 1")
            if count > 1 and stop <= start:
                raise argparse.ArgumentTypeError(f"{text!r}: STOP must be greater than START")
            return np.geomspace(start, stop, count)
        return np.array([positive_float(part) for part in text.split(",")])
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r} is neither START:STOP:N nor a comma-separated list of numbers > 0"
        ) from None
