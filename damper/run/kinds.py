"""The stage kinds a scene can use, in the order the plan lists them.

A new kind (as ``backbone`` and ``optimal_load`` in :mod:`.backbone_stages`) is added here, with the
results it provides in ``damper.scene.schema.RESULTS``.
"""
from __future__ import annotations

from .backbone_stages import Backbone, OptimalLoad
from .contact_stages import Condense, Normal, Tangential
from .element_stages import FMU, Loop
from .mistuning_stages import Mistuning
from .response_stages import FRF
from .upd_frf_stages import UPDFRF

KINDS = (Condense(), Normal(), Tangential(), Loop(), FMU(), FRF(), Backbone(), OptimalLoad(),
         UPDFRF(), Mistuning())
