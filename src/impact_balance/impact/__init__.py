"""Impact models.

The paper's frictional impact at a point contact (:mod:`.model`), the experimental
contact-aware model (:mod:`.contact_aware`) and the held-stance jumps built on it
(:mod:`.held_stance`).
"""

__all__ = ["IMPACT_MODELS"]

#: The impact models the commands (``--impact-model``) and the governor (``impact_model``) take:
#: "floating", the paper's (the robot floats through the impact, :mod:`.model`), and
#: "held-stance" (its sustained contacts take impulses too, :mod:`.held_stance`).
IMPACT_MODELS = ("floating", "held-stance")
