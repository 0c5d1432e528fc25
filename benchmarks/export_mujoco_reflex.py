"""The catalogue design's collision reflex in MuJoCo against the report's impulse, sample by sample.

Runs the smoke size of the UR5 and the two planar two-link studies, exports each catalogue design's MJCF and
runs :mod:`collision_reflex.export.mujoco_reflex` on its first samples. Per sample it prints the spread of the
closed form's variants (the robot moving at detection, the links moving along the wall, the links blocked along
the wall in the sensing phase: how much the report's assumptions matter there), the report's impulse, MuJoCo's,
their relative difference, the detection time against the closed form's ``t1``, the impulse until detection
against the closed form's ``m_f v0 + F_s^2 / (2 k v0)``, the impulse of a later touch (not counted) and the wall
time. Then, at the UR5's first sample with a spread within 1 % (the test's sample), how the wall's stiffness and
damping and the step move MuJoCo's impulse, and what the arm simulator's own wall (1000 x the joints' stiffness,
damping ratio 2) gives there; the same at a sample near a singularity.
Run: ``PYTHONPATH=src python benchmarks/export_mujoco_reflex.py [SAMPLES]`` (needs ``mujoco``; SAMPLES per study,
default 12).
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from pathlib import Path

from collision_reflex.cli import main as crx
from collision_reflex.export import export_design, read_run_design
from collision_reflex.export.mujoco_reflex import mujoco_reflex
from collision_reflex.export.reflex_sample import (
    MODEL_SPREAD,
    contact_sample,
    model_spread,
    sample_closed_form,
)
from collision_reflex.model.impulse import collision_times, phase_impulses

STUDIES = ("ur5", "two_link_planetary", "two_link_paper")
ROOT = Path(__file__).resolve().parents[1]


def _run(study: str, folder: Path) -> tuple[Path, Path]:
    out = folder / study
    argv = ["run", str(ROOT / "studies" / f"{study}.yaml"), "--out", str(out), "--quiet", "--smoke"]
    assert crx([*argv, "--executor", "serial"]) == 0
    model = folder / f"{study}.xml"
    export_design(out, "catalogue", "mjcf", model)
    return out, model


def _row(run: Path, model: Path, sample: int, **options: float) -> str:
    """MuJoCo against the report at a sample: impulses, detection against the closed form's t1, wall time."""
    start = time.perf_counter()
    result = mujoco_reflex(run, sample, model, **options)
    seconds = time.perf_counter() - start
    design = read_run_design(run, "catalogue")
    closed = sample_closed_form(design, contact_sample(run, sample))
    v0 = design.approach_velocity
    phases = phase_impulses(closed.m_f, closed.k, closed.k_m, closed.threshold, closed.a, v0, "at_rest")
    t1, _ = collision_times(closed.m_f, closed.k, closed.k_m, closed.threshold, closed.a, v0)
    detected = 100 * (result.detected_impulse / float(phases.initial + phases.sensing) - 1)
    return (
        f"{result.predicted:9.5f} {result.impulse:9.5f} {100 * result.relative_difference:+8.2f} "
        f"{1e3 * result.detection_time:7.3f} {1e3 * t1:7.3f} {detected:+8.2f} "
        f"{result.impulse_after:8.4f} {seconds:6.1f}"
    )


def main() -> None:
    count = int(sys.argv[1]) if len(sys.argv) > 1 else 12
    load = os.getloadavg()
    print(
        f"machine load (1, 5, 15 min): {load[0]:.1f}, {load[1]:.1f}, {load[2]:.1f} on {os.cpu_count()} cores"
    )
    header = "sample  spread%  reported    MuJoCo   diff%  det ms   t1 ms  Idet d%    after      s"
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(scratch)
        runs = {study: _run(study, folder) for study in STUDIES}
        for study, (run, model) in runs.items():
            samples = len(json.loads((run / "designs.json").read_text())["samples"]["config_index"])
            print(f"\n{study} (smoke), catalogue design; impulses [N*s], after: a later touch, not counted")
            print(header)
            for sample in range(min(count, samples)):
                spread = 100 * model_spread(run, sample)
                print(f"{sample:6d} {spread:8.2f} {_row(run, model, sample)}", flush=True)
        run, model = runs["ur5"]
        chosen = next(s for s in range(32) if model_spread(run, s) <= MODEL_SPREAD)
        print(f"\nur5 sample {chosen}: the wall and the step (defaults: 1e6, 30, 20)")
        _walls(run, model, chosen, arm_simulator=True)
        print("\nur5 sample 8, near a singularity (m_f 171 kg): the same")
        _walls(run, model, 8, arm_simulator=False)


def _walls(run: Path, model: Path, sample: int, arm_simulator: bool) -> None:
    """The sample with the wall stiffer or softer, more damped, at a finer step (and the arm simulator's wall)."""
    print("contact/k_m  damping  steps  reported    MuJoCo   diff%  det ms   t1 ms  Idet d%    after      s")
    cases = [(1e6, 30.0, 20.0), (1e5, 30.0, 20.0), (1e6, 10.0, 40.0), (1e6, 30.0, 40.0)]
    for ratio, damping, steps in cases + ([(1e3, 2.0, 20.0)] if arm_simulator else []):
        options = {
            "contact_stiffness_ratio": ratio,
            "contact_damping_ratio": damping,
            "steps_per_period": steps,
        }
        print(f"{ratio:11.0e} {damping:8.0f} {steps:6.0f} {_row(run, model, sample, **options)}", flush=True)


if __name__ == "__main__":
    main()
