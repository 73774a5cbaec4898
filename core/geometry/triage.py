"""Triage of validation flags: which problems an edit made, and which ones to show.

A :class:`Baseline` remembers the severity of every flag of a reference report (the
structure as read) by its kind and place (``Flag.kind``, ``Flag.where``); a later flag is
then :data:`NEW` (no such flag in the baseline), :data:`WORSE` (its severity grew by more
than :data:`WORSE_BY`) or :data:`AS_READ`. A :class:`TriageFilter` (kinds, a minimum
severity, one of :data:`SCOPES`) chooses the flags to show, and :func:`triage` applies it to a report:
one dictionary look-up per flag.

An old entry can carry hundreds of flags before any edit (4HHB: 1,301, 1TIM: 390); the
default scope, :data:`EDITED_OR_SEVERE`, shows those an edit made or worsened and, of the
others, only those worse than :data:`SEVERE` times their tolerance (4HHB: 493, 1TIM: 28
before an edit); :data:`EDITED` shows only the former, :data:`EVERYTHING` every flag.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from core.geometry.validation import KINDS, Flag, ValidationReport

NEW, WORSE, AS_READ = "new", "worse", "as read"
"""The novelty of a flag against a baseline (see :meth:`Baseline.novelty`)."""
EDITED_OR_SEVERE, EDITED, EVERYTHING = "edited or severe", "edited", "everything"
SCOPES = (EDITED_OR_SEVERE, EDITED, EVERYTHING)
"""Scopes of a :class:`TriageFilter`: the new and worse flags and the others above :data:`SEVERE`,
the new and worse flags only, or every flag."""
WORSE_BY = 0.25
"""A flag of the baseline is worse when its severity grew by more than this: a quarter of its
tolerance (0.0125 Å on a peptide bond, 0.1 Å more overlap for a clash, 1.8–2.5° on a junction
angle, 7.5° on ω), far above the rounding of rigid-body moves, which leave a residue's own
geometry as it was."""
SEVERE = 2.0
"""Flags worse than this many times their tolerance are shown in every scope."""


@dataclass(frozen=True)
class Baseline:
    """Severities of the flags of a reference report, by ``(kind, where)``."""

    severity: Mapping[tuple[str, str], float]

    @classmethod
    def of(cls, report: ValidationReport) -> Baseline:
        """The baseline of a whole-structure ``report`` (the worst flag of a place, if it has two)."""
        severity: dict[tuple[str, str], float] = {}
        for flag in reversed(report.flags):  # worst first: the worst one of a place is written last
            severity[flag.kind, flag.where] = flag.severity
        return cls(severity)

    def novelty(self, flag: Flag) -> str:
        """:data:`NEW`, :data:`WORSE` or :data:`AS_READ`: ``flag`` against the baseline."""
        before = self.severity.get((flag.kind, flag.where))
        if before is None:
            return NEW
        return WORSE if flag.severity > before + WORSE_BY else AS_READ


@dataclass(frozen=True)
class TriageFilter:
    """Which flags to show.

    Attributes
    ----------
    kinds : the kinds shown (of :data:`~core.geometry.validation.KINDS`).
    min_severity : only flags of a larger severity are shown (0: every flag).
    scope : one of :data:`SCOPES` (default :data:`EDITED_OR_SEVERE`).
    """

    kinds: frozenset[str] = frozenset(KINDS)
    min_severity: float = 0.0
    scope: str = EDITED_OR_SEVERE

    def __post_init__(self) -> None:
        unknown = set(self.kinds) - set(KINDS)
        if unknown:
            raise ValueError(f"kinds must be among {KINDS}; got {sorted(unknown)}")
        if self.scope not in SCOPES:
            raise ValueError(f"scope must be one of {SCOPES}; got {self.scope!r}")
        object.__setattr__(self, "kinds", frozenset(self.kinds))

    def shows(self, flag: Flag, novelty: str) -> bool:
        """Whether ``flag``, of this ``novelty``, passes the filter."""
        return (flag.kind in self.kinds and flag.severity > self.min_severity
                and (self.scope == EVERYTHING or novelty != AS_READ
                     or (self.scope == EDITED_OR_SEVERE and flag.severity > SEVERE)))


@dataclass(frozen=True)
class Triaged:
    """A report sorted out by :func:`triage`.

    Attributes
    ----------
    flags : the flags shown, worst first.
    novelty : the novelty of each shown flag.
    new, worse : new and worse flags per kind, of the whole report (shown or not).
    """

    flags: tuple[Flag, ...]
    novelty: tuple[str, ...]
    new: dict[str, int]
    worse: dict[str, int]


def triage(report: ValidationReport, baseline: Baseline, triage_filter: TriageFilter = TriageFilter()) -> Triaged:
    """The flags of ``report`` that ``triage_filter`` shows against ``baseline``, with the
    counts of new and worse flags per kind."""
    new, worse = dict.fromkeys(KINDS, 0), dict.fromkeys(KINDS, 0)
    flags, novelty = [], []
    novelty_of, shows = baseline.novelty, triage_filter.shows
    for flag in report.flags:
        state = novelty_of(flag)
        if state == NEW:
            new[flag.kind] += 1
        elif state == WORSE:
            worse[flag.kind] += 1
        if shows(flag, state):
            flags.append(flag)
            novelty.append(state)
    return Triaged(tuple(flags), tuple(novelty), new, worse)
