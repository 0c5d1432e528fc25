"""Actuator hardware: motors and their scaling laws, gearboxes, actuators, the catalogue, actuator sweeps."""
