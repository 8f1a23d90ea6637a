"""Tests of ``impact_balance.impact``."""
