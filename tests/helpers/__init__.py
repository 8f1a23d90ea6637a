"""Helpers shared by the tests (no test here): command runs, synthetic logs, hostile values, figure
layout."""
