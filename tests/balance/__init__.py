"""Tests of ``impact_balance.balance``."""
