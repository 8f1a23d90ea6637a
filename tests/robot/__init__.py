"""Tests of ``impact_balance.robot``."""
