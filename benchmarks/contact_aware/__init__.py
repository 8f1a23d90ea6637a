"""The contact-aware governor benchmark of ``benchmarks/contact_aware_governor.py``, one concept
per module.

- :mod:`.journal`: the journalled trials (resumable under ``--out``) and the wall trials' slim
  summary.
- :mod:`.trials`: ``score`` (the governed trials) and ``sweep`` (ungoverned, the inset rule), and
  their tables.
- :mod:`.preload`: the preload model, its error on the training stances, the ramp's jumps, and
  ``bounds``.
- :mod:`.trace`: ``trace``, one logged approach: after the impact, at the contact posture, the
  warm/cold branches.
"""
