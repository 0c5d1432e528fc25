"""Collision experiments: force-time traces, the measured impulse, and the model fitted to them."""
