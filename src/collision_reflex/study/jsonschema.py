"""The JSON Schema of study files, for editors that complete and check YAML.

For example through yaml-language-server's ``# yaml-language-server: $schema=study.schema.json``.
"""

from __future__ import annotations

from typing import Any

from pydantic import TypeAdapter

from .schema import ActuatorStudy, ArmStudy


def study_json_schema() -> dict[str, Any]:
    """JSON Schema (draft 2020-12) accepting every valid study file, arm and actuator studies alike."""
    schema = TypeAdapter(ArmStudy | ActuatorStudy).json_schema()
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "collision-reflex design study",
        "description": (
            "A design study for collision-reflex: quantities are numbers in SI units or strings with units "
            "('60 mm', '1.3 N*m')."
        ),
        **schema,
    }
