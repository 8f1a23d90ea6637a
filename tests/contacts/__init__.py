"""Tests of ``impact_balance.contacts``."""
