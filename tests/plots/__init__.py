"""Tests of ``impact_balance.plots``."""
