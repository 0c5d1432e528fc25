"""The report's impulse surfaces: one per distinct design featured."""

from __future__ import annotations

import numpy as np

from collision_reflex.optimize.pareto import RESOLUTION
from collision_reflex.report.figures import _distinct_surfaces


def test_designs_of_the_same_impulses_share_one_surface_and_their_titles():
    rng = np.random.default_rng(0)
    chosen = rng.uniform(0.1, 2.0, 96)
    featured = {
        # The Panda study's flat front: the first Pareto design 2e-5 from the chosen one at most.
        "chosen design": {"impulses": chosen.tolist()},
        "Pareto design 0 (best mean impulse)": {"impulses": (chosen * (1 + 2e-5)).tolist()},
        # One sample 3 x RESOLUTION away: another picture.
        "Pareto design 7 (best actuator mass)": {
            "impulses": np.where(np.arange(96) == 5, chosen * (1 + 3 * RESOLUTION), chosen).tolist()
        },
    }
    surfaces = _distinct_surfaces(featured)
    assert list(surfaces) == [
        "chosen design = Pareto design 0 (best mean impulse)",
        "Pareto design 7 (best actuator mass)",
    ]
    assert surfaces["chosen design = Pareto design 0 (best mean impulse)"] is featured["chosen design"]
    # Distinct designs keep their own surfaces, in order.
    apart = {name: {"impulses": (chosen * (1 + 0.01 * i)).tolist()} for i, name in enumerate("abc")}
    assert list(_distinct_surfaces(apart)) == ["a", "b", "c"]
