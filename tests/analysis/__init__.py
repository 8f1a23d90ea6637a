"""Tests of ``impact_balance.analysis``."""
