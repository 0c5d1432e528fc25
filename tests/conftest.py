"""Shared test settings and set-ups: figures render off-screen; the Panda case of the active-set tests."""

from typing import NamedTuple

import matplotlib
import numpy as np
import pytest

import collision_reflex as cr

matplotlib.use("Agg")


class DesignCase(NamedTuple):
    """An arm, its contact samples and the optimiser's inputs: ``build_problem`` takes them in this order."""

    arm: cr.Arm
    samples: cr.ContactSamples
    space: cr.DesignSpace
    technology: cr.ActuatorTechnology
    constraints: cr.Constraints


@pytest.fixture(scope="session")
def panda_case():
    """``panda_case(configurations)``: the Panda on ``configurations`` random configurations x 4 random
    directions (seed 7), motors scaled from the reference motor with their reflected inertia on the finger, a
    1 kg payload; the active-set tests' case, at the size each needs."""

    def case(configurations: int) -> DesignCase:
        rng = np.random.default_rng(7)
        arm = cr.Arm.from_example_robot_data("panda")
        samples = cr.ContactSamples.grid(
            arm.kinematics(arm.sample_configurations(configurations, rng)), rng.normal(size=(4, 3))
        )
        space = cr.DesignSpace(
            stator_diameter=(0.02, 0.15),
            gear_ratio=(1.0, 100.0),
            software_stiffness=(100.0, 1e4),
            threshold=(5.0, 40.0),
            approach_velocity=(0.05, 1.0),
        )
        technology = cr.ActuatorTechnology(
            cr.reference_motor(), mechanical_stiffness=5000.0, reflected_inertia_in="finger"
        )
        constraints = cr.Constraints(payload=1.0, safety_factor=1.5, threshold_floor=5.0)
        return DesignCase(arm, samples, space, technology, constraints)

    return case
