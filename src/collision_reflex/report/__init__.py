"""Run results as files: designs, Pareto table, figures and the actuator sizing report.

The files are ``designs.json``, ``pareto.csv``, the figures and the self-contained HTML (and PDF) actuator
sizing report.
"""

from .outputs import pareto_rows, render_report, write_outputs

__all__ = ["pareto_rows", "render_report", "write_outputs"]
