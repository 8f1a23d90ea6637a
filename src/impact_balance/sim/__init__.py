"""Simulation of a scenario in MuJoCo (model, joint models, trials, balance controller, falls)."""
