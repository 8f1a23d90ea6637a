"""Tests of ``impact_balance.governor``."""
