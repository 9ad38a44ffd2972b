"""The thesis's studies as reproducible drivers (``damper study ...``).

Each driver recomputes its study from scratch (reusing the condensation cache),
returns a JSON-able dict with the thesis's numbers beside ours, and draws its
figures on request. Library computations live in ``contact_core``.
"""
