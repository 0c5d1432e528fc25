"""Run results as files: ``designs.json``, ``pareto.csv``, figures and the self-contained HTML (and PDF)
actuator sizing report.
"""

from .outputs import pareto_rows, render_report, write_outputs

__all__ = ["pareto_rows", "render_report", "write_outputs"]
