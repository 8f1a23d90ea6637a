"""Trials in MuJoCo: an impact trial (:mod:`.impact_trial`) and its measurement (:mod:`.measure`), a balance trial (:mod:`.balance_trial`) with its set-up, outcome, log and video."""
