"""``index`` and ``search`` on real entries, through ``main``: serial, in worker processes and on
a Dask cluster; the hits of serine proteases and ubiquitin; what they do with bad input."""

import json
import shutil
from pathlib import Path

import gemmi
import numpy as np
import pytest

from app.main import main
from core.analysis.fold_index import FIELDS, FoldIndex

DATA = Path(__file__).resolve().parents[2] / "data"
ENTRIES = ["3PTB.pdb.gz", "1BMA.pdb.gz", "3SGB.pdb.gz", "1ACB.pdb.gz", "1UBQ.pdb.gz", "2K39_CA-only.pdb.gz",
           "1TIM.pdb.gz", "1BPI.pdb.gz", "1L2Y.pdb.gz", "1BNA.pdb.gz"]


def run(capsys, *argv) -> tuple[int, str, str]:
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """Serine proteases, ubiquitin twice, a TIM barrel, BPTI, the Trp-cage and a DNA duplex."""
    folder = tmp_path_factory.mktemp("entries")
    for name in ENTRIES:
        shutil.copy(DATA / name, folder / name)
    return folder


@pytest.fixture(scope="module")
def index_file(folder, tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("index") / "folds.npz"
    assert main(["index", str(folder), "-o", str(path), "--jobs", "1"]) == 0
    return path


def read_index(path: Path) -> FoldIndex:
    return FoldIndex.read(path)


def test_the_index_holds_every_protein_chain_of_20_residues_or_more(index_file):
    index = read_index(index_file)
    chains = sorted(zip(np.asarray(index.entries).tolist(), np.asarray(index.chains).tolist()))
    # 1ACB: chymotrypsin E and eglin c I (70); 1TIM: A and B; 3SGB: E and the inhibitor I (56);
    # 1L2Y (20 residues) counts, 1BNA (DNA) has none
    assert chains == [("1ACB", "E"), ("1ACB", "I"), ("1BMA", "A"), ("1BPI", "A"), ("1L2Y", "A"), ("1TIM", "A"),
                      ("1TIM", "B"), ("1UBQ", "A"), ("2K39_CA-only", "A"), ("3PTB", "A"), ("3SGB", "E"), ("3SGB", "I")]
    assert index.descriptors.dtype == np.float16 and index.descriptors.shape == (12, 247)
    assert index.profiles.dtype == np.float16 and index.profiles.shape == (12, 32)
    assert len(index.coordinates) == index.lengths.sum() == len(index.sequences) == len(index.states)
    with np.load(index_file, allow_pickle=False) as archive:  # plain arrays: no pickled objects
        assert set(archive.files) == set(FIELDS)


def test_search_finds_the_serine_proteases(index_file, capsys):
    status, out, _ = run(capsys, "search", DATA / "3PTB.pdb.gz", index_file, "--json", "--top", "5")
    report = json.loads(out)
    assert status == 0 and report["searched"] == 12 and report["query_length"] == 223
    assert report["scored"] == report["aligned"] == 12  # at most the index
    hits = [(h["entry"], h["chain"]) for h in report["hits"]]
    assert hits[0] == ("3PTB", "A") and report["hits"][0]["tm_score"] == pytest.approx(1.0)
    assert set(hits[1:4]) == {("1BMA", "A"), ("1ACB", "E"), ("3SGB", "E")}
    by_entry = {h["entry"]: h for h in report["hits"]}
    assert by_entry["1BMA"]["tm_score"] == pytest.approx(0.955, abs=0.02)  # TM-align's, by trypsin
    assert by_entry["3SGB"]["tm_score"] == pytest.approx(0.602, abs=0.02)
    assert by_entry["1BMA"]["identity"] > 0.3 > by_entry["3SGB"]["identity"]
    assert [h["fold_score"] for h in report["hits"]] == sorted((h["fold_score"] for h in report["hits"]), reverse=True)
    assert all(h["evalue"] < 1e-5 for h in report["hits"][:4]) and report["max_evalue"] == 10


def test_search_by_chain_as_a_table(index_file, capsys):
    status, out, _ = run(capsys, "search", f"{DATA / '1UBQ.pdb.gz'}:A", index_file, "--top", "3")
    lines = out.splitlines()
    assert status == 0 and "chain A (76 residues) against 12 chains" in lines[0]
    assert lines[3].split()[1:3] == ["1UBQ", "A"]
    assert lines[4].split()[1:3] == ["2K39_CA-only", "A"]  # its NMR model next
    assert float(lines[4].split()[4]) < 1e-8 and float(lines[4].split()[6]) > 0.9  # E-value, TM-score


def test_an_index_in_worker_processes_and_on_a_dask_cluster_is_the_same(folder, index_file, tmp_path, capsys):
    from dask.distributed import LocalCluster

    expected = read_index(index_file)
    status, _, _ = run(capsys, "index", folder, "-o", tmp_path / "two.npz", "--jobs", "2")
    assert status == 0
    with LocalCluster(processes=False, n_workers=1, threads_per_worker=2, dashboard_address=None,
                      protocol="tcp") as cluster:
        status, out, _ = run(capsys, "index", folder, "-o", tmp_path / "dask.npz", "--scheduler",
                             cluster.scheduler_address)
    assert status == 0 and "indexed 12 chains of 9 file(s)" in out and "skipped 1 file(s)" in out
    for name in ("two.npz", "dask.npz"):
        found = read_index(tmp_path / name)
        for field in FIELDS[1:]:
            assert np.array_equal(getattr(found, field), getattr(expected, field)), field


def test_an_index_is_never_overwritten_unless_asked(folder, tmp_path, capsys):
    target = tmp_path / "folds.npz"
    target.write_text("mine")
    status, _, err = run(capsys, "index", folder / "1UBQ.pdb.gz", "-o", target, "--jobs", "1")
    assert status == 1 and "refusing to overwrite" in err and target.read_text() == "mine"
    status, _, _ = run(capsys, "index", folder / "1UBQ.pdb.gz", "-o", target, "--jobs", "1", "--overwrite")
    assert status == 0 and len(read_index(target)) == 1
    assert [p.name for p in tmp_path.iterdir()] == ["folds.npz"]  # no temporary file left


def test_a_peptide_is_refused_as_a_query(index_file, tmp_path, capsys):
    """A query of fewer than 20 residues (none such is indexed) is refused, saying why: its
    TM-scores and E-values mean little (ubiquitin's first 5 residues matched 16 chains of the
    README's index at a TM-score of 0.5 or more). The Trp-cage's 20 residues are searched."""
    structure = gemmi.read_structure(str(DATA / "1UBQ.pdb.gz"))
    chain = structure[0]["A"]
    for k in range(len(chain) - 1, 11, -1):
        del chain[k]
    structure.write_pdb(str(tmp_path / "peptide.pdb"))
    status, _, err = run(capsys, "search", tmp_path / "peptide.pdb", index_file)
    assert status == 1 and "chain A has 12 residue(s): a fold search needs a chain of 20 or more" in err
    status, out, _ = run(capsys, "search", DATA / "1L2Y.pdb.gz", index_file)
    assert status == 0 and "chain A (20 residues)" in out


def test_the_index_given_first_is_named_as_such(index_file, capsys):
    """The usual slip, ``search DB QUERY``, says which argument goes where."""
    status, _, err = run(capsys, "search", index_file, DATA / "1UBQ.pdb.gz")
    assert status == 1 and "a fold index, not a structure: give the query's structure first" in err
    assert "Traceback" not in err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["index", "{data}/1BNA.pdb.gz", "-o", "{tmp}/x.npz"], "no protein chain of 20 residues or more"),
        (["index", "{data}/1UBQ.pdb.gz", "-o", "{tmp}/missing/x.npz"], "no such folder"),
        (["search", "{data}/1UBQ.pdb.gz", "{tmp}/none.npz"], "no such file"),
        (["search", "{data}/1UBQ.pdb.gz", "{tmp}"], "not a regular file (a folder"),
        (["search", "{data}/1UBQ.pdb.gz", "{data}/1UBQ.pdb.gz"], "not a ribbonwave fold index"),
        (["search", "{data}/1UBQ.pdb.gz:Z", "{data}/1UBQ.pdb.gz"], "no protein chain 'Z'"),
        (["search", "{data}/nothing.pdb", "{data}/1UBQ.pdb.gz"], "no such file"),
    ],
)
def test_bad_input(argv, message, tmp_path, capsys):
    argv = [a.replace("{data}", str(DATA)).replace("{tmp}", str(tmp_path)) for a in argv]
    status, _, err = run(capsys, *argv)
    assert status == 1 and message in err and "Traceback" not in err


@pytest.mark.parametrize(("damage", "message"), [
    ("no chain", "a fold index of no chain"),
    ("infinite descriptors", "descriptors or profiles that are not finite numbers"),
    ("a profile of NaN", "descriptors or profiles that are not finite numbers"),
    ("a chain of 0 residues", "chains shorter than 20 residues"),
    ("infinite coordinates", "non-finite coordinates"),
    ("lengths that disagree", "its arrays disagree"),
    ("a flipped bit in the coordinates", "changed since it was indexed"),
    ("a residue renamed", "changed since it was indexed"),
    ("a 3Di state changed", "changed since it was indexed"),
])
def test_a_damaged_index_asks_to_be_built_again(index_file, tmp_path, capsys, damage, message):
    """Each of these gave a traceback (ZeroDivisionError, IndexError, ...); each now says what is
    wrong and how to rebuild the index (#37)."""
    from core.analysis.fold_index import FORMAT

    index = read_index(index_file)
    arrays = {name: np.array(getattr(index, name)) for name in FIELDS[1:]}
    if damage == "no chain":
        arrays = {name: array[:0] for name, array in arrays.items()}
    elif damage == "infinite descriptors":
        arrays["descriptors"][3] = np.inf
    elif damage == "a profile of NaN":
        arrays["profiles"][2] = np.nan
    elif damage == "a chain of 0 residues":
        arrays["lengths"][1], arrays["lengths"][2] = 0, arrays["lengths"][1] + arrays["lengths"][2]
    elif damage == "infinite coordinates":
        arrays["coordinates"][:] = np.inf
    elif damage == "a flipped bit in the coordinates":  # every chain: whichever the search reads is damaged
        arrays["coordinates"].view(np.uint32)[::7] ^= 1 << 12
    elif damage == "a residue renamed":
        arrays["sequences"][::5] = b"X"
    elif damage == "a 3Di state changed":
        arrays["states"][::5] = (arrays["states"][::5] + 1) % 20
    else:
        arrays["lengths"][0] += 5
    damaged = tmp_path / "damaged.npz"
    np.savez(damaged, format=np.array(FORMAT), **arrays)
    status, _, err = run(capsys, "search", DATA / "3PTB.pdb.gz", damaged)
    assert status == 1 and message in err and "index the files again" in err and "Traceback" not in err
