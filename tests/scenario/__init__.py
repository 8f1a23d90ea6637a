"""Tests of ``impact_balance.scenario``."""
