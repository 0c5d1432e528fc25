"""Seeded fuzz of the input files a user hands in: duty cycles, force traces (``crx fit``) and catalogues.

Each surface gets 60 mutations of a valid file (characters deleted, inserted or changed, lines doubled or dropped,
the file cut short). Every one is read, or refused with the package's own error (a located one-line message),
within two seconds: never another exception, never a hang. The export surface is in ``test_bounded_input.py``,
study files in ``test_fuzz_studies.py``.
"""

from __future__ import annotations

import random
import time
from pathlib import Path

import numpy as np
import pytest

from collision_reflex.arm.duty_cycle import DutyCycle
from collision_reflex.errors import CollisionReflexError
from collision_reflex.experiments.traces import read_traces
from collision_reflex.hardware.catalogue import read_entries

ROOT = Path(__file__).resolve().parents[1]
MUTATIONS = 60
INSERTED = [
    "\n",
    ",",
    "-",
    "e",
    "9",
    "[",
    "]",
    " ",
    "\x00",
    "é",
    "#",
    "nan",
    "inf",
    "1e400",
    ":",
    "'",
    '"',
    "{",
    "*",
]


def _mutated(text: str, rng: random.Random) -> str:
    chars = list(text)
    for _ in range(rng.randint(1, 4)):
        kind = rng.randrange(6)
        i = rng.randrange(max(len(chars), 1))
        if kind == 0 and chars:
            del chars[i]
        elif kind == 1:
            chars.insert(i, rng.choice(INSERTED))
        elif kind == 2 and chars:
            chars[i] = rng.choice("0123456789.-e,\n ")
        elif kind in (3, 4):
            lines = "".join(chars).split("\n")
            j = rng.randrange(len(lines))
            if kind == 3:
                lines.insert(j, lines[j])
            elif len(lines) > 2:
                del lines[j]
            chars = list("\n".join(lines))
        else:
            chars = chars[: rng.randrange(len(chars) + 1)]
    return "".join(chars)


CYCLE = "time [s],j1 [deg],j2 [deg]\n" + "".join(
    f"{k * 0.02:.3f},{30 * np.sin(k * 0.1):.4f},{20 * np.cos(k * 0.1):.4f}\n" for k in range(60)
)
SURFACES = {
    "duty_cycle": (CYCLE, ".csv", lambda path: DutyCycle.from_csv(path, ["j1", "j2"])),
    "trace": ((ROOT / "studies/traces/u8_soft/u8_soft_v120mm.csv").read_text(), ".csv", read_traces),
    "catalogue": (
        (ROOT / "designs/gearboxes.yaml").read_text(),
        ".yaml",
        lambda p: read_entries(p, "gearboxes"),
    ),
}


@pytest.mark.parametrize("surface", list(SURFACES))
def test_a_mutated_input_file_is_read_or_refused_by_the_package(surface, tmp_path):
    base, suffix, read = SURFACES[surface]
    rng = random.Random(f"fuzz-{surface}")
    for trial in range(MUTATIONS):
        path = tmp_path / f"{trial}{suffix}"
        path.write_text(_mutated(base, rng), encoding="utf-8")
        start = time.perf_counter()
        try:
            read(path)
        except CollisionReflexError:
            pass
        assert time.perf_counter() - start < 2.0, (surface, trial)
