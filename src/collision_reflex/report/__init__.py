"""Run results as files: designs, Pareto table, figures and the actuator sizing report.

The files are ``designs.json``, ``pareto.csv``, the figures and the self-contained HTML (and PDF) actuator
sizing report.

The report's modules import the optimiser (and with it CasADi) only inside the functions that need its tables
(``# lazy: casadi``): ``crx export`` imports this package (through :mod:`.files`) and needs no optimiser.
"""

from .outputs import pareto_rows, render_report, write_outputs

__all__ = ["pareto_rows", "render_report", "write_outputs"]
