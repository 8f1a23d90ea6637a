"""Balance areas.

The LIPM (:mod:`.lipm`), the ZMP support area and CoM velocity area (:mod:`.areas`), and why a
stance cannot balance (:mod:`.infeasibility`).
"""

__all__: list[str] = []
