"""Tests of ``impact_balance.solvers``."""
