"""Impact models.

The paper's frictional impact at a point contact (:mod:`.model`) and the experimental
contact-aware model (:mod:`.contact_aware`).
"""

__all__: list[str] = []
