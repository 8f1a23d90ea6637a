"""Tests of ``impact_balance.sim``."""
