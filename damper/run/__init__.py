"""Running scenes: the stage graph (:mod:`.graph`), the stage kinds (:mod:`.kinds`),
the runner that plans, computes or loads each stage and writes the output folder
(:mod:`.runner`), and progress display (:mod:`.progress`)."""
