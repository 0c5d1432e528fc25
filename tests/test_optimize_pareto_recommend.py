"""How a run's recommended design is found: repeats merged within the solver tolerance, the best of every solve
for the study's objective, never a design a reported point dominates (hand-made results)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from collision_reflex.optimize.dominance import MERGE_TOLERANCE, merge_repeats, same_point
from collision_reflex.optimize.epsilon import ANCHOR_SLACK
from collision_reflex.optimize.pareto import ParetoSet
from collision_reflex.optimize.recommend import RESOLUTION, recommend

NAMES = ("worst_case_impulse", "actuator_mass")


def result(impulse: float, mass: float):
    """A solved design as far as the recommendation reads it: its objective values [N*s, kg]."""
    objectives = {"worst_case_impulse": impulse, "mean_impulse": impulse / 2, "actuator_mass": mass}
    return SimpleNamespace(numpy_objectives={**objectives, "approach_velocity": 0.5})


def front(*points):
    return ParetoSet(NAMES, tuple(points), labels=tuple(f"p{i}" for i in range(len(points))))


def test_the_merge_tolerance_covers_the_solver_and_the_anchor_slack():
    # IPOPT's tol (1e-8) repeats an optimum to ~1e-7; the anchors hold their first objective within ANCHOR_SLACK.
    assert MERGE_TOLERANCE >= 10 * max(1e-7, ANCHOR_SLACK)
    assert MERGE_TOLERANCE <= 1e-4  # far below a difference a designer acts on (0.01 %)


def test_repeats_within_the_tolerance_are_merged_and_counted():
    a = result(0.5, 0.4)
    repeat = result(0.5 * (1 + 0.3 * MERGE_TOLERANCE), 0.4 * (1 - 0.3 * MERGE_TOLERANCE))
    other = result(0.5 * (1 + 3 * MERGE_TOLERANCE), 0.3)
    kept, merged = merge_repeats([a, repeat, other], NAMES)
    assert kept == [a, other] and merged == [repeat]
    # Just outside the tolerance in one objective: a different point.
    apart = result(0.5, 0.4 * (1 + 2 * MERGE_TOLERANCE))
    assert not same_point(a.numpy_objectives, apart.numpy_objectives, NAMES)
    assert merge_repeats([a, apart], NAMES) == ([a, apart], [])


def test_a_front_point_better_in_the_studys_objective_is_recommended():
    optimum = result(0.50, 0.40)  # a local optimum
    points = front(result(0.48, 0.45), result(0.49, 0.30))
    found = recommend(optimum, points, "worst_case_impulse")
    assert found.pareto_index == 0 and found.result is points.points[0]
    assert "better worst case impulse" in found.reason and "0.48 vs 0.5" in found.reason


def test_a_dominating_front_point_is_recommended_with_the_reason():
    optimum = result(
        0.48604, 2.193
    )  # the Panda case of issue 12: both front points beat it on both objectives
    points = front(result(0.48551, 0.391), result(0.48560, 0.380))
    found = recommend(optimum, points, "mean_impulse")  # not a front objective: dominance decides
    assert found.pareto_index in (0, 1) and "dominates the single-objective optimum" in found.reason
    # With the study's objective on the front, the dominating point best in it, unless a lighter one is within
    # RESOLUTION of it: here point 1 is 0.02 % worse in impulse and 3 % lighter.
    assert recommend(optimum, points, "worst_case_impulse").pareto_index == 1
    assert recommend(optimum, points, "actuator_mass").pareto_index == 1
    apart = front(result(0.48551, 0.391), result(0.48551 * (1 + 2 * RESOLUTION), 0.380))
    assert recommend(optimum, apart, "worst_case_impulse").pareto_index == 0


def test_equal_within_tolerance_but_heavier_is_dominated():
    # The two-link case: the impulse anchor is 1e-6 worse in impulse (its slack) and lighter.
    optimum = result(0.14728616, 0.20042)
    anchor = result(0.14728616 * (1 + ANCHOR_SLACK), 0.20009)
    found = recommend(optimum, front(anchor, result(0.1478, 0.0108)), "worst_case_impulse")
    assert found.pareto_index == 0 and "within the solver tolerance" in found.reason
    # Labelled as the sweep labels it, the point is said to be the objective's anchor: the expected way a
    # front's end beats the optimum (its mass minimised with the impulse held).
    labelled = ParetoSet(
        NAMES,
        (anchor, result(0.1478, 0.0108)),
        labels=("anchor: worst_case_impulse", "anchor: actuator_mass"),
    )
    found = recommend(optimum, labelled, "worst_case_impulse")
    assert found.reason.startswith(
        "Pareto design 0 (the anchor of worst case impulse: it minimised, then the other objectives with it held)"
        " dominates the single-objective optimum"
    )
    assert (
        "anchor of"
        not in recommend(optimum, front(anchor, result(0.1478, 0.0108)), "worst_case_impulse").reason
    )


def test_an_optimum_that_is_a_front_point_is_that_point():
    optimum = result(0.5, 0.4)
    same = result(0.5 * (1 + 0.1 * MERGE_TOLERANCE), 0.4)
    found = recommend(optimum, front(same, result(0.6, 0.2)), "worst_case_impulse")
    assert found.pareto_index == 0 and "which is Pareto design 0" in found.reason


def test_an_undominated_optimum_stays_recommended():
    optimum = result(0.45, 0.5)  # better impulse than the front, heavier: a trade-off, not dominated
    found = recommend(optimum, front(result(0.48, 0.45), result(0.49, 0.30)), "worst_case_impulse")
    assert found.pareto_index is None and found.result is optimum and found.source == "optimum"
    assert recommend(optimum, None, "worst_case_impulse").result is optimum


@pytest.mark.parametrize("objective", ["worst_case_impulse", "actuator_mass", "mean_impulse"])
def test_the_recommendation_is_never_dominated_brute_force(objective):
    """Every optimum against a grid of fronts: no reported point dominates the recommendation."""
    points = front(result(0.40, 0.9), result(0.42, 0.6), result(0.47, 0.3), result(0.55, 0.1))
    for impulse in (0.38, 0.41, 0.44, 0.50, 0.60):
        for mass in (0.05, 0.2, 0.5, 0.7, 1.0):
            found = recommend(result(impulse, mass), points, objective).result.numpy_objectives
            for p in points.points:
                theirs = p.numpy_objectives
                no_worse = all(theirs[n] <= found[n] for n in NAMES)
                better = any(theirs[n] < found[n] * (1 - 1e-9) for n in NAMES)
                assert not (no_worse and better), (impulse, mass, theirs)


@pytest.mark.parametrize("starts", [0, 1.5, True])
def test_single_optimum_refuses_a_bad_start_count_before_building(starts):
    from collision_reflex.errors import InvalidParameter
    from collision_reflex.optimize.optimum import single_optimum

    with pytest.raises(InvalidParameter, match="starts"):
        single_optimum(None, "worst_case_impulse", starts=starts)  # type: ignore[arg-type]


def test_a_front_tie_that_is_worse_in_the_studys_own_objective_does_not_win():
    """The UR5 case: the front (impulse vs approach velocity) does not weigh mass, the study's objective does.
    A front point that ties the optimum on the front but is five times heavier must not replace it."""
    names = ("worst_case_impulse", "approach_velocity")
    optimum = result(0.6354, 0.3156)
    heavy_tie = result(0.6354, 1.6411)
    faster = SimpleNamespace(
        numpy_objectives={**result(8.67, 1.64).numpy_objectives, "approach_velocity": 0.68}
    )
    points = ParetoSet(names, (heavy_tie, faster), labels=("p0", "p1"))
    weighted = (("actuator_mass", 0.1), ("worst_case_impulse", 1.0))
    found = recommend(optimum, points, weighted)
    assert found.result is optimum and found.pareto_index is None
    # Judged on the front's objectives alone the heavy tie is "the same point"; being alike in the impulse, the
    # lighter of the two (the optimum) is recommended all the same.
    found = recommend(optimum, points, "worst_case_impulse")
    assert found.result is optimum and "which is Pareto design 0" in found.reason


def test_the_lightest_of_the_designs_alike_in_impulse_is_recommended():
    # The Panda study's case: the 4-start optimum is 0.037 % better in mean impulse than the front's lightest
    # design and carries 2.8 times its actuator mass; below RESOLUTION that difference ranks no design.
    optimum = result(2 * 0.4856403, 1.1156)  # result() halves the impulse into the mean impulse
    points = ParetoSet(
        ("mean_impulse", "actuator_mass"),
        (result(2 * 0.4857377, 0.3947327), result(2 * 0.4858196, 0.3947324)),
        labels=("p0", "p1"),
    )
    found = recommend(optimum, points, "mean_impulse")
    assert found.pareto_index == 1 and found.result is points.points[1]
    assert "within 0.1 % of it in mean impulse" in found.reason and "0.3947 kg" in found.reason
    assert found.reason.startswith("the single-objective optimum")  # why it was the best, then why not it
    # 0.2 % better is a difference the recommendation acts on: the optimum stays.
    better = result(2 * 0.4858196 * (1 - 2 * RESOLUTION), 1.1156)
    assert recommend(better, points, "mean_impulse").result is better
    # Mass and speed objectives are ranked as they are.
    assert recommend(optimum, points, "actuator_mass").result is not optimum


@pytest.mark.parametrize("objective", ["worst_case_impulse", "mean_impulse"])
def test_no_reported_design_alike_in_impulse_is_lighter_brute_force(objective):
    """Every optimum against fronts with close points: the recommendation is undominated and no undominated
    design within RESOLUTION of the best impulse is lighter."""
    close = 0.4 * (1 + 0.5 * RESOLUTION)
    points = front(result(0.40, 0.9), result(close, 0.6), result(0.47, 0.3), result(0.55, 0.1))
    for impulse in (0.3999, 0.40, 0.4001, 0.41, 0.50):
        for mass in (0.05, 0.5, 0.7, 1.0):
            optimum = result(impulse, mass)
            found = recommend(optimum, points, objective).result.numpy_objectives
            designs = [p.numpy_objectives for p in points.points]
            if not points.all_dominating(optimum.numpy_objectives, MERGE_TOLERANCE, (*NAMES, objective)):
                designs.append(optimum.numpy_objectives)
            least = min(d[objective] for d in designs)
            for d in designs:
                no_worse = all(d[n] <= found[n] for n in NAMES)
                better = any(d[n] < found[n] * (1 - 1e-9) for n in NAMES)
                assert not (no_worse and better), (impulse, mass, d)
                if d[objective] <= least * (1 + RESOLUTION):
                    assert found["actuator_mass"] <= d["actuator_mass"] * (1 + MERGE_TOLERANCE), (
                        impulse,
                        mass,
                    )
