"""Shared test settings: figures render off-screen."""

import matplotlib

matplotlib.use("Agg")
