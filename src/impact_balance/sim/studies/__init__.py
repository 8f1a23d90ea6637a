"""Studies built on balance trials.

- :mod:`.validate`: the fall threshold of an impact, against the criteria's predictions;
- :mod:`.push`: push grids, against the criteria's predictions;
- :mod:`.wall`: the governed approach to a wall;
- :mod:`.journal`: journals of finished trials; :mod:`.scores`: how predictions are scored.
"""

__all__: list[str] = []
