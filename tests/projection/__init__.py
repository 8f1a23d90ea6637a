"""Tests of ``impact_balance.projection``."""
