"""Reports of runs: the one-page HTML report (:mod:`.html`)."""
