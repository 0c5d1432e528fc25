"""Design studies: YAML files that describe a robot, its actuators, samples, design variables and objectives.

:func:`load_study` reads and validates one (every problem at once, each with its line); :func:`study_json_schema`
is the JSON Schema for editors; :func:`resolved_study` is the study with every default and unit made explicit.
"""

from .jsonschema import study_json_schema
from .load import LoadedStudy, load_study, parse_study
from .resolve import resolved_study, resolved_yaml
from .schema import ActuatorStudy, ArmStudy, Study

__all__ = [
    "ActuatorStudy",
    "ArmStudy",
    "LoadedStudy",
    "Study",
    "load_study",
    "parse_study",
    "resolved_study",
    "resolved_yaml",
    "study_json_schema",
]
