"""Does a run's reported worst case hold on fresh samples it was not optimised on?

    PYTHONPATH=src python benchmarks/worst_case_fresh.py RUN_FOLDER [--samples 20000] [--seed 1] [--design recommended]
        [--region thigh_knee]

Reads the run's ``designs.json`` (the design, the contact domain it reports and the study), draws ``--samples``
configurations uniformly within the joint limits and directions uniformly on the sphere (the circle for a planar
arm) with its own generator, keeps the pairs inside the reported domain (smallest singular value of the contact
Jacobian at least the floor; the guarded move ``J^+ u v0`` within the joint speed limits at the design's approach
velocity) and evaluates the design's impulse there (NumPy path). It prints the fraction of the box the domain
keeps, the largest fresh impulse against the reported worst case (``worst_case.domain``) and their ratio, and the
same without the domain (every fresh pair), to show what the domain excludes. With ``--region`` it also prints the
slowest permissible speed against that ISO/TS 15066 body region over the fresh pairs in the domain (rotors on the
links, as a study's ``constraints.body_region`` takes it) against the design's approach velocity.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path)
    parser.add_argument("--samples", type=int, default=20_000)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument(
        "--design", default="recommended", help="recommended, chosen, catalogue, or a Pareto index"
    )
    parser.add_argument("--region", help="an ISO/TS 15066 body region (crx safety --list-regions)")
    args = parser.parse_args()

    from collision_reflex.arm.domain import smallest_singular_values, unit_speed_joint_rates
    from collision_reflex.optimize.evaluate import sample_impulses
    from collision_reflex.optimize.results import record_design
    from collision_reflex.optimize.samples import ContactSamples
    from collision_reflex.study.load import load_study
    from collision_reflex.study.problems import study_setup
    from collision_reflex.study.resolve import resolve_study

    results = json.loads((args.run / "designs.json").read_text())
    setup = study_setup(resolve_study(load_study(args.run / "study.resolved.yaml")))
    arm, technology = setup.arm, setup.technology
    if args.design.isdigit():
        record = results["pareto"]["points"][int(args.design)]
    else:  # the catalogue design sits in its own block
        record = results["catalogue"]["design"] if args.design == "catalogue" else results[args.design]
    design = record_design(record, setup.technology.sensing)
    domain = results["domain"]
    rng = np.random.default_rng(args.seed)
    started = time.perf_counter()
    lower, upper = np.array(domain["joint_lower"]), np.array(domain["joint_upper"])
    q = arm.configuration(rng.uniform(lower, upper, size=(args.samples, lower.size)))
    u = rng.normal(size=(args.samples, arm.task_dim))
    u /= np.linalg.norm(u, axis=1)[:, None]
    kinematics = arm.kinematics(q)
    jacobian = kinematics.jacobian
    limits = np.array([np.inf if v is None else v for v in domain["joint_speed_limit"]])
    floor_ok = smallest_singular_values(jacobian) >= domain["min_singular_value"]
    rates = np.abs(unit_speed_joint_rates(jacobian, u)) * design.approach_velocity
    inside = floor_ok & np.all(rates <= limits, axis=1)
    with np.errstate(all="ignore"):
        impulses = sample_impulses(ContactSamples(kinematics, u, np.arange(args.samples)), technology, design)
    # The catalogue design has no worst-case search of its own: its objective, over the run's samples.
    sampled = record["objectives"]["worst_case_impulse"]
    reported = record["worst_case"]["domain"] if "worst_case" in record else sampled
    fresh = float(impulses[inside].max())
    print(f"run: {args.run}  design: {args.design} ({record['label']})  load {os.getloadavg()[0]:.2f}")
    print(
        f"domain: sigma_min >= {domain['min_singular_value']:.4g} m (reach {domain['reach']:.4g} m), "
        f"v0 = {design.approach_velocity:.4g} m/s; keeps {inside.mean():.1%} of {args.samples} fresh pairs "
        f"(configurations {floor_ok.mean():.1%})"
    )
    print(
        f"reported worst case {reported:.6g} N*s (sampled {record.get('worst_case', {}).get('sampled', sampled):.6g}); "
        f"fresh in the domain {fresh:.6g} N*s: ratio {fresh / reported:.4f}"
    )
    print(
        f"fresh without the domain {float(np.nanmax(impulses)):.6g} N*s: ratio "
        f"{float(np.nanmax(impulses)) / reported:.3f}  ({time.perf_counter() - started:.1f} s)"
    )
    if args.region:
        from collision_reflex.optimize.body_region import region_speeds
        from collision_reflex.study.body_regions import load_body_regions

        region = load_body_regions()[args.region]
        chosen = np.flatnonzero(inside)
        fresh_samples = ContactSamples(kinematics, u[chosen], chosen)
        speeds = region_speeds(fresh_samples, design, region)
        print(
            f"{args.region}: slowest permissible speed over the fresh pairs in the domain {speeds.min():.6g} m/s "
            f"against the approach {design.approach_velocity:.6g} m/s (ratio {speeds.min() / design.approach_velocity:.4f}); "
            f"{int(np.sum(design.approach_velocity > speeds * (1 + 1e-6)))} of {chosen.size} pairs below it"
        )


if __name__ == "__main__":
    main()
