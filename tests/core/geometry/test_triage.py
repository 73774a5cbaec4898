"""Triage of validation flags against the structure as read, on real entries and a real edit."""

from dataclasses import replace
from pathlib import Path

import pytest

from core.geometry.triage import (
    AS_READ,
    EDITED,
    EVERYTHING,
    NEW,
    SEVERE,
    WORSE,
    WORSE_BY,
    Baseline,
    TriageFilter,
    triage,
)
from core.geometry.validation import KINDS, validate
from core.protein.model import EditableModel
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"


@pytest.mark.parametrize("name", ["4HHB.pdb.gz", "1TIM.pdb.gz"])
def test_before_an_edit_the_default_filter_shows_the_severe_flags_only(name):
    report = validate(read_structure(DATA / name))
    triaged = triage(report, Baseline.of(report))
    assert triaged.flags == tuple(f for f in report.flags if f.severity > SEVERE)
    assert 0 < len(triaged.flags) < 0.4 * len(report.flags)  # 4HHB: 493 of 1,301; 1TIM: 28 of 390
    assert set(triaged.novelty) == {AS_READ}
    assert triaged.new == triaged.worse == dict.fromkeys(KINDS, 0)
    everything = triage(report, Baseline.of(report), TriageFilter(scope=EVERYTHING))
    assert everything.flags == report.flags
    assert not triage(report, Baseline.of(report), TriageFilter(scope=EDITED)).flags


@pytest.fixture(scope="module")
def edited():
    """Ubiquitin as read and after pushing a loop into the protein (bad junctions, clashes)."""
    structure = read_structure(DATA / "1UBQ.pdb.gz")
    model = EditableModel(structure)
    model.apply(model.move_point(0, 4, 8, [-3.0, 4.0, -6.0]))
    return validate(structure), validate(structure, model.coords)


def test_an_edit_makes_new_flags_that_the_default_filter_shows(edited):
    as_read, report = edited
    baseline = Baseline.of(as_read)
    before = {(f.kind, f.where) for f in as_read.flags}
    made = [f for f in report.flags if (f.kind, f.where) not in before]
    assert len(made) > 100 and any(f.severity < SEVERE for f in made)  # mild new flags too
    triaged = triage(report, baseline)
    assert [f for f, novelty in zip(triaged.flags, triaged.novelty) if novelty == NEW] == made
    assert triaged.new == {kind: sum(f.kind == kind for f in made) for kind in KINDS}
    assert set(triaged.flags) == set(made)  # the file's own clash, mild, is as it was and not shown
    assert triage(report, baseline, TriageFilter(scope=EDITED)).flags == tuple(made)


def test_a_flag_is_worse_beyond_the_margin(edited):
    as_read, _ = edited
    baseline = Baseline.of(as_read)
    flag = as_read.flags[0]
    assert baseline.novelty(flag) == AS_READ
    assert baseline.novelty(replace(flag, severity=flag.severity + 0.9 * WORSE_BY)) == AS_READ
    assert baseline.novelty(replace(flag, severity=flag.severity + 1.1 * WORSE_BY)) == WORSE
    assert baseline.novelty(replace(flag, severity=flag.severity - 1.0)) == AS_READ  # better
    assert baseline.novelty(replace(flag, where="A:MET1 N / A:GLY76 O")) == NEW
    mild = replace(as_read, flags=(replace(flag, severity=1.2),))  # a mild flag as read is not shown...
    assert not triage(mild, Baseline.of(mild)).flags
    worse = replace(as_read, flags=(replace(flag, severity=1.5),))  # ...until it gets worse
    triaged = triage(worse, Baseline.of(mild))
    assert triaged.novelty == (WORSE,) and triaged.worse["clash"] == 1


def test_kinds_and_severity_filter_the_flags(edited):
    _, report = edited
    baseline = Baseline.of(report)  # nothing new: the scope lets through what is severe
    clashes = triage(report, baseline, TriageFilter(kinds={"clash"}, scope=EVERYTHING))
    assert clashes.flags == tuple(f for f in report.flags if f.kind == "clash")
    severe = triage(report, baseline, TriageFilter(min_severity=4.0, scope=EVERYTHING))
    assert severe.flags == tuple(f for f in report.flags if f.severity > 4.0)
    assert 0 < len(severe.flags) < len(triage(report, baseline).flags) < len(report.flags)
    assert not triage(report, baseline, TriageFilter(kinds=())).flags


def test_bad_filters_are_refused():
    with pytest.raises(ValueError, match="kinds"):
        TriageFilter(kinds={"clash", "bump"})
    with pytest.raises(ValueError, match="scope"):
        TriageFilter(scope="new")
    assert TriageFilter(kinds=["clash"]) == TriageFilter(kinds=frozenset({"clash"}))
