"""Tests of ``impact_balance.geometry``."""
