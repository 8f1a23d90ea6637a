"""Tests of ``impact_balance.criteria``."""
