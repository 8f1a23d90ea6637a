"""Tests of ``impact_balance.gui``."""
