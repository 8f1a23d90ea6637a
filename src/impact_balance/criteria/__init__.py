"""Balance criteria: the maximum contact velocity (:mod:`.com`) and the paper's QP in joint velocities (:mod:`.qp`)."""
