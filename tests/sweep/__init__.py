"""Tests of ``impact_balance.sweep``."""
