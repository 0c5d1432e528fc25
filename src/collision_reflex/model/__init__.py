"""The collision-reflex model: plain arithmetic that works on floats, NumPy arrays and CasADi symbols alike."""
