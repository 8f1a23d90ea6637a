"""Robot models: loading and per-thread data (:mod:`.robot`), mesh files (:mod:`.meshes`), whole-body IK for stances (:mod:`.ik`)."""
