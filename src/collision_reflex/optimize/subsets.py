"""Problems on subsets of a problem's contact samples: the subset itself, and the subset problems kept."""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import TYPE_CHECKING

import numpy as np

from .samples import ContactSamples

if TYPE_CHECKING:
    from .problem import DesignProblem


def sample_subset(samples: ContactSamples, index: np.ndarray) -> ContactSamples:
    """The samples at ``index`` (integer indices), with every configuration's kinematics kept.

    A subset of searched samples alone (none drawn) takes its mean over them.
    """
    index = np.asarray(index, dtype=int)
    assert samples.speed_cap is not None and samples.drawn is not None  # set by ContactSamples
    drawn = samples.drawn[index]
    return ContactSamples(
        samples.kinematics,
        samples.directions[index],
        samples.config_index[index],
        tuple(samples.labels[i] for i in index) if samples.labels else (),
        samples.speed_cap[index],
        drawn if np.any(drawn) else None,
    )


SUBSET_PROBLEMS = 4
"""Problems on subsets of the samples kept per process (with their solvers), the last used kept longest: every
epsilon point's first active set is the first anchor's, and every catalogue combination of a snap warm-starts
from the continuous problem on the optimum's last active samples, so each is built once per process."""
_SUBSETS: OrderedDict[tuple[Hashable, ...], tuple[object, DesignProblem]] = OrderedDict()


def release_subsets() -> None:
    """Drop the kept subset problems (:func:`kept_problem`)."""
    _SUBSETS.clear()


def kept_problem(
    key: tuple[Hashable, ...],
    samples: ContactSamples,
    build: Callable[[], DesignProblem],
    holds: object = None,
) -> DesignProblem:
    """``build()``, a problem on ``samples``, built once per process for ``key`` and those samples.

    The last :data:`SUBSET_PROBLEMS` are kept. ``holds``: an object that ``key`` names by its ``id``, kept with
    the problem so that its id is not another object's while the entry lives.
    """
    full_key = (*key, samples.config_index.tobytes(), samples.directions.tobytes())
    kept = _SUBSETS.get(full_key)
    if kept is None or kept[0] is not holds:
        kept = _SUBSETS[full_key] = (holds, build())
        while len(_SUBSETS) > SUBSET_PROBLEMS:
            _SUBSETS.popitem(last=False)
    _SUBSETS.move_to_end(full_key)
    return kept[1]
