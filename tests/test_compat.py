"""The deprecated-keyword decorator: old spellings still work, warn, and never pass silently twice."""

import warnings

import pytest

from collision_reflex._compat import renamed_keywords


@renamed_keywords(finger_mass="m_f")
def _impulse(m_f: float, v0: float) -> float:
    return m_f * v0


def test_new_name_does_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert _impulse(m_f=2.0, v0=3.0) == 6.0


def test_old_name_warns_and_maps():
    with pytest.warns(DeprecationWarning, match="'finger_mass' is deprecated; call it 'm_f'"):
        assert _impulse(finger_mass=2.0, v0=3.0) == 6.0


def test_both_names_is_an_error():
    with pytest.raises(TypeError, match="both 'finger_mass' and 'm_f'"):
        _impulse(finger_mass=2.0, m_f=2.0, v0=3.0)
