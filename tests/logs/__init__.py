"""Tests of ``impact_balance.logs``."""
