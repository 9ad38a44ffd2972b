"""Multi-harmonic balance with alternating frequency-time evaluation of the
friction elements (the C core in ``fmu_src``) and arc-length continuation."""
