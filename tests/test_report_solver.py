"""The report says how each design was solved: on all samples or on an active set of them, and how many."""

from __future__ import annotations

from collision_reflex.report.html import solved_by


def _record(method: str | None, active: int | None, samples: int) -> dict:
    solver = {"status": "Solve_Succeeded"}
    if method is not None:
        solver.update(method=method, active_samples=active)
    return {"solver": solver, "impulses": [0.1] * samples}


def test_a_full_solve_names_every_sample() -> None:
    assert solved_by(_record("full NLP", 336, 336)) == "full NLP: all 336 samples"


def test_an_active_set_solve_names_its_subset_of_all_samples() -> None:
    assert solved_by(_record("active set", 72, 4096)) == "active set: 72 of 4096 samples"


def test_a_mean_impulse_problem_says_why_it_solved_every_sample() -> None:
    why = "all samples: the mean impulse (objective or bound) needs every sample"
    assert solved_by(_record(why, 96, 96)) == f"full NLP: {why} (96)"


def test_a_record_written_before_the_method_was_recorded_prints_a_dash() -> None:
    assert solved_by(_record(None, None, 18)) == "–"
