"""The speed benchmark of ``benchmarks/run.py`` (issue 3), one concept per module.

- :mod:`.timing`: timed cases, round-robin measurement, statistics, progress lines.
- :mod:`.polygons`: polygon comparison for the answer checks (independent of the library).
- :mod:`.projection`: the area projection, ours vs pypoman vs our Bretl/HiGHS path.
- :mod:`.pipeline`: the pipeline stage by stage, and the maximum contact velocity alone.
- :mod:`.stances`: one bundled stance measured whole.
- :mod:`.scaling`: scaling with the number of contacts and of friction-cone edges.
- :mod:`.profiling`: ``--profile`` (cProfile and a micro-breakdown).
- :mod:`.machine`: the machine and the versions.
- :mod:`.checks`: the answer checks (they set the exit status).
- :mod:`.targets`: the performance targets (informative).
- :mod:`.report`: the text tables.
- :mod:`.interleave`, :mod:`.worker`: ``--baseline``, two trees timed in one run, interleaved.
- :mod:`.stage_job`, :mod:`.ticks`: what one side times (``run.py``, ``governor.py``).
- :mod:`.compat`: the differences between the project's versions (feature detection).
"""
