"""Checks of a bladed-disk result that tell whether its numbers mean what they say
(``damper upd frf`` and ``damper upd mistuning``): a maximum at the end of its band is no
peak, and a damper open over most of the period rattles rather than rubs.

Frequencies in any one unit (Hz or rad/s); loads in N.
"""
from __future__ import annotations

#: A peak within END_RTOL of the band's width plus END_FREQ_RTOL of its top frequency from
#: one of its ends lies at that end: a bounded search of a maximum at the end stops short of
#: it by ~sqrt(eps) |omega| (Brent's bounded method: a free tuned peak at the end of 380 ...
#: 424 Hz came out 2.5e-8 of the frequency, 2.4e-7 of the width, inside; 1e-9 let it pass).
END_RTOL, END_FREQ_RTOL = 1e-6, 1e-7

#: Share of the period every contact (or face) is open at the peak above which the damper
#: is said to rattle rather than rub: it then carries its load in short impacts (UPD-24 at
#: CF 120 N: 0.48-0.55 at F0 100 N, 0.94-0.95 at F0 1000 N, 0.98 at 1e4 N; CF 30 N, F0 30 N,
#: the low end of the default load sweep: 0.57-0.68). At F0 1000 N the ring's time
#: integration (--check-steady-state) met the harmonic balance's peak within 0.33 %: the
#: airfoil's amplitude holds, the impacts' contact forces are what a few harmonics miss.
RATTLE_LIFT_OFF = 0.9


def at_band_end(w: float, lo: float, hi: float) -> bool:
    """Whether the frequency ``w`` lies at an end of the band [lo, hi] (:data:`END_RTOL`,
    :data:`END_FREQ_RTOL`)."""
    return min(abs(w - lo), abs(w - hi)) <= END_RTOL * (hi - lo) + END_FREQ_RTOL * hi


def rattle_warning(lift_off, f0: float, cf: float, H: int, hint: str = "") -> str | None:
    """The warning line when every contact's share of the period lifted off (``lift_off``,
    one per contact or face) exceeds :data:`RATTLE_LIFT_OFF`, else None; ``hint`` is added
    to what it says to do."""
    if not lift_off or min(lift_off) <= RATTLE_LIFT_OFF:
        return None
    return (f"warning: every contact is open over at least {100 * min(lift_off):.0f} % of the period at the "
            f"peak (F0 {f0:g} N against CF {cf:g} N): the damper rattles rather than rubs, its load carried "
            f"in short impacts whose forces H = {H} harmonics resolve poorly{hint}; raise the CF or lower F0 "
            "for a damper that rubs")
