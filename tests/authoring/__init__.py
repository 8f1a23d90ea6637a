"""Tests of ``impact_balance.authoring``."""
