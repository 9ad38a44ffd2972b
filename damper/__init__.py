"""The application layer: what a user drives.

The ``damper`` command (:mod:`damper.cli`) and, in time, scenes, studies,
benchmarks and stress runs live here. It imports the libraries
(``contact_core``, ``fmu_src``, ``harmonic_balance``); no library imports it.
"""
