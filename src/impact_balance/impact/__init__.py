"""Impact models.

The paper's frictional impact at a point contact (:mod:`.model`), the experimental
contact-aware model (:mod:`.contact_aware`) and the held-stance jumps built on it
(:mod:`.held_stance`).
"""

__all__: list[str] = []
