"""Studies built on trials: the fall threshold (:mod:`.validate`), push grids (:mod:`.push`), the wall approach (:mod:`.wall`), trial journals (:mod:`.journal`) and scores (:mod:`.scores`)."""
