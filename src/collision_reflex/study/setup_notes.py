"""What the report says of an arm study's setup.

Where the motors' speed limits come from, what the transmissions are, and where each joint's reflected inertia
acts.
"""

from __future__ import annotations

from ..hardware.gearbox_scaling import GEARBOX_SCALING
from ..hardware.gearboxes import ScaledGearbox
from ..hardware.motors import scaling_law
from ..optimize.technology import PLACEMENT_STIFFNESS_RATIO
from .arm_setup import ArmSetup


def speed_limits(setup: ArmSetup) -> str | None:
    """Where the motors' speed limits come from, for the report (None without a duty cycle or a rated motion)."""
    if not setup.constraints.moves:
        return None
    motor = setup.technology.motors[0]
    law = scaling_law(setup.technology.scaling_law).speed
    return (
        f"Speed limits: the reference motor {motor.name} turns at most {motor.max_speed:.4g} rad/s (its "
        f"catalogue entry's figure); a scaled motor's limit follows "
        f"omega_max ∝ (l/l0)^{law.length_exponent:g} (r/r0)^{law.diameter_exponent:g}. "
        f"{law.source}"
    )


def placement_sentences(setup: ArmSetup) -> list[str]:
    """Where each joint's reflected inertia acts in the impact, when the joints differ or a rule chose it."""
    joints = list(setup.arm.joint_names)
    in_finger = setup.technology.finger_joints(len(joints))
    ratios = setup.placement_ratios
    if ratios is None and len(set(in_finger)) < 2:
        return []
    named = [f"{joint}" + ("" if ratios is None else f" ({ratios[j]:.3g})") for j, joint in enumerate(joints)]
    finger = [n for n, f in zip(named, in_finger, strict=True) if f]
    robot = [n for n, f in zip(named, in_finger, strict=True) if not f]
    lines = [
        "Reflected inertia: "
        + (
            f"per joint from its transmission's stiffness against the contact's "
            f"({setup.study.reflected_inertia_in.contact_stiffness:.4g} N/m, seen at the joint through its "  # type: ignore[union-attr]
            "median squared moment arm; in brackets the contact's stiffness over the transmission's): "
            if ratios is not None
            else "per joint as the study gives it: "
        )
        + (
            f"in the impact (a stiff transmission) at {', '.join(finger)}"
            if finger
            else "in the impact nowhere"
        )
        + (f"; behind the joint spring (a compliant joint) at {', '.join(robot)}" if robot else "")
        + "."
    ]
    if ratios is not None and finger:
        lines.append(
            "Against an object softer than its transmission a joint's rotor moves with the links, but there the "
            "contact's own compliance spreads the impact, which the closed form (a rigid object) does not: the "
            'simulator finds it overestimates the impulse (documentation: Time-domain simulation, "Where the arm closed form holds"); treat the '
            "impulse as an upper estimate."
        )
    if ratios is not None:
        between = [
            joints[j]
            for j, r in enumerate(ratios)
            if 1 / PLACEMENT_STIFFNESS_RATIO < r < PLACEMENT_STIFFNESS_RATIO
        ]
        if between:
            lines.append(
                f"Warning: at {', '.join(between)} the contact and the transmission are of like stiffness "
                f"(within {PLACEMENT_STIFFNESS_RATIO:g}x): the simulator validates neither placement there "
                '(documentation: Time-domain simulation, "Where the arm closed form holds"); simulate the design before trusting its impulse.'
            )
    return lines


def transmissions(setup: ArmSetup) -> list[str]:
    """What the joints' transmissions are, for the report: scaled gearboxes, and geared joints without a model."""
    joints = list(setup.arm.joint_names)
    gearboxes = setup.technology.joint_gearboxes(len(joints))
    ratios = setup.space.per_joint("gear_ratio", len(joints))
    lines = []
    scaled: dict[ScaledGearbox, list[str]] = {}
    for joint, gearbox in zip(joints, gearboxes, strict=True):
        if isinstance(gearbox, ScaledGearbox):
            scaled.setdefault(gearbox, []).append(joint)
    for gearbox, named in scaled.items():
        mass, inertia, torque = (law.diameter for law in GEARBOX_SCALING[gearbox.kind])
        low, high = gearbox.ratio_range
        lines.append(
            f"Transmissions of {', '.join(named)}: a {gearbox.kind} gearbox scaled from {gearbox.reference.name} "
            f"to carry its motor's peak torque N tau_p (mass ∝ torque^{mass / torque:.3g}, input inertia ∝ "
            f"torque^{inertia / torque:.3g}: Saerens et al. 2019 at the reference's length), its mass in the "
            f"actuator mass and its input inertia in N^2 (J_m + J_g). Its ratios "
            f"({', '.join(f'{r:g}' for r in gearbox.ratios)}) are relaxed to the range {low:g} to {high:g} in the "
            "continuous designs; the catalogue design takes a unit of the catalogue at a ratio it is sold with."
        )
    lines += placement_sentences(setup)
    bare = [
        joint
        for joint, gearbox, bounds in zip(joints, gearboxes, ratios, strict=True)
        if gearbox is None and bounds.upper > 1
    ]
    if bare:
        lines.append(
            f"Warning: {', '.join(bare)} may be geared (N up to {max(b.upper for b in ratios):g}) but have no "
            "transmission model: their gearboxes weigh nothing and have no inertia, so a larger ratio costs "
            "nothing but the reflected rotor inertia. Give actuators.gearbox (a catalogue unit, its figures, or "
            "{scaled_from: ...}), or fix the gear ratio at 1 for direct drive."
        )
    return lines
