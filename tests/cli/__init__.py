"""Tests of ``impact_balance.cli``."""
