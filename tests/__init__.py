"""The test suite: one folder per package folder of ``impact_balance``; shared helpers in
``tests.helpers``."""
