"""The ``analyze`` and ``compare`` commands on real entries, through ``main``."""

import csv
import json
import os
import re
import shutil
import socket
from pathlib import Path

import numpy as np
import pytest
import tmtools
from matplotlib.image import imread

from app.main import main
from core.protein.reading import read_structure

DATA = Path(__file__).resolve().parents[2] / "data"
ENTRIES = ["1UBQ.pdb.gz", "1TIM.pdb.gz", "4HHB.pdb.gz", "1F9V.pdb.gz", "2O9S_A.pdb.gz", "7Z9T.cif.gz"]
SUMMARY_HEADER = ["ribbon", "mode", "depth", "class", "n_residues", "rms", "sd"]


def run(capsys, *argv) -> tuple[int, str, str]:
    status = main([str(a) for a in argv])
    captured = capsys.readouterr()
    return status, captured.out, captured.err


def read_csv(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


@pytest.fixture(scope="module")
def database(tmp_path_factory) -> Path:
    """A folder of entries in two sub-folders, a DNA-only entry, a broken file and a non-structure file."""
    folder = tmp_path_factory.mktemp("database")
    (folder / "more").mkdir()
    for k, name in enumerate(ENTRIES):
        shutil.copy(DATA / name, folder / ("more" if k % 2 else ".") / name)
    shutil.copy(DATA / "1BNA.pdb.gz", folder / "1BNA.pdb.gz")
    (folder / "broken.cif").write_text("data_broken\n_atom_site.id 1\n")
    (folder / "notes.txt").write_text("not a structure, not picked up\n")
    return folder


@pytest.fixture(scope="module")
def analysed(database, tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("analysis")
    status = main(["analyze", str(database), "-o", str(out), "--jobs", "2"])
    assert status == 0
    return out


def test_analyze_writes_the_tables_and_reports_skipped_files(database, tmp_path, capsys):
    status, out, err = run(capsys, "analyze", database, "-o", tmp_path / "out", "--jobs", "2", "--max-depth", "4")
    assert status == 0
    assert "analysing" in err and "100%" in err  # the progress bar
    assert "skipped" in err and "1BNA.pdb.gz" in err and "broken.cif" in err
    skipped = read_csv(tmp_path / "out" / "skipped.csv")
    assert sorted(Path(row["file"]).name for row in skipped) == ["1BNA.pdb.gz", "broken.cif"]
    assert all(row["reason"] for row in skipped)
    residues = read_csv(tmp_path / "out" / "residues.csv")
    expected = sum(read_structure(DATA / name).n_residues for name in ENTRIES)
    assert len(residues) == expected
    assert f"analysed {len(ENTRIES)} file(s)" in out and f"{expected} residues" in out
    assert "67 residues in 1 file(s) without HELIX/SHEET records: helix/sheet/other computed by DSSP" in out
    assert re.search(r"rms at 1/4 of the segments \(depth 2\), Å +\d\.\d\d +\d\.\d\d +2\.1\n", out)
    assert re.search(r"rms at 1/8 of the segments \(depth 3\), Å +\d\.\d\d +\d\.\d\d +3\.3\n", out)
    assert re.search(r"depth where the rms passes 3\.8 Å +[23]\.\d\d +[23]\.\d\d ", out)


def test_summary_has_exactly_the_contract_columns_and_agrees_with_the_residue_rows(analysed):
    with (analysed / "summary.csv").open(newline="") as handle:
        assert next(csv.reader(handle)) == SUMMARY_HEADER
    summary = read_csv(analysed / "summary.csv")
    assert {(r["ribbon"], r["mode"]) for r in summary} == {
        (ribbon, mode) for ribbon in ("peptide", "calpha") for mode in ("integer", "fractional")
    }
    assert {r["class"] for r in summary} == {"all", "helix", "sheet", "other"}
    assert {float(r["depth"]) for r in summary if r["mode"] == "fractional"} == set(np.arange(0, 6.01, 0.5))
    residues = read_csv(analysed / "residues.csv")
    for row in summary:
        name = f"{row['ribbon']}_{row['mode']}_{row['depth']}"
        values = np.array([float(r[name]) for r in residues
                           if r[name] and (row["class"] == "all" or r["class"] == row["class"])])
        assert int(row["n_residues"]) == len(values)
        assert float(row["rms"]) == pytest.approx(np.sqrt(np.mean(values**2)), abs=2e-3)  # residues.csv: 3 decimals
        assert float(row["sd"]) == pytest.approx(np.std(values), abs=2e-3)
    by_key = {(r["ribbon"], r["mode"], r["depth"], r["class"]): float(r["rms"]) for r in summary}
    assert by_key[("calpha", "integer", "0", "all")] == 0.0
    assert 0.9 < by_key[("peptide", "integer", "0", "all")] < 1.5
    assert by_key[("peptide", "integer", "2", "all")] < by_key[("peptide", "integer", "3", "all")]


def test_fig7_shows_every_class(analysed):
    image = imread(analysed / "fig7.png")
    assert image.shape[0] > 600 and image.shape[1] > 800
    red, green, blue = image[..., 0], image[..., 1], image[..., 2]
    assert np.count_nonzero((red > 0.7) & (green < 0.3) & (blue < 0.3)) > 200  # helix series
    assert np.count_nonzero((blue > 0.6) & (red < 0.3)) > 200  # sheet series


def test_one_process_and_a_dask_cluster_give_the_same_numbers(database, analysed, tmp_path, capsys):
    from dask.distributed import LocalCluster

    status, _, _ = run(capsys, "analyze", database, "-o", tmp_path / "serial", "--jobs", "1")
    assert status == 0
    with LocalCluster(processes=False, n_workers=1, threads_per_worker=2, dashboard_address=None,
                      protocol="tcp") as cluster:
        status, _, _ = run(capsys, "analyze", database, "-o", tmp_path / "dask", "--scheduler", cluster.scheduler_address)
    assert status == 0
    expected = (analysed / "summary.csv").read_text()
    assert (tmp_path / "serial" / "summary.csv").read_text() == expected
    assert (tmp_path / "dask" / "summary.csv").read_text() == expected
    assert (tmp_path / "dask" / "residues.csv").read_text() == (analysed / "residues.csv").read_text()


def test_reference_selection_options(tmp_path, capsys):
    args = ["analyze", DATA / "4HHB.pdb.gz", DATA / "2O9S_A.pdb.gz", "--jobs", "1", "--chains", "longest",
            "--gaps", "join", "--termini", "calpha", "--ss", "records"]
    status, out, _ = run(capsys, *args, "-o", tmp_path / "reference")
    assert status == 0 and "2 curves, 213 residues" in out  # 4HHB chain D (146, in three pieces) + 2O9S (67)
    assert "67 residues in 1 file(s) without HELIX/SHEET records: counted only in class 'all'" in out
    residues = read_csv(tmp_path / "reference" / "residues.csv")
    assert {r["chain"] for r in residues if r["entry"] == "4HHB"} == {"D"}
    assert {r["curve"] for r in residues} == {"0"}
    assert {r["class"] for r in residues if r["file"].endswith("2O9S_A.pdb.gz")} == {""}  # no records: only in 'all'
    summary = read_csv(tmp_path / "reference" / "summary.csv")
    helix = next(r for r in summary if (r["ribbon"], r["mode"], r["depth"], r["class"]) == ("peptide", "integer", "0", "helix"))
    assert int(helix["n_residues"]) == sum(r["class"] == "helix" for r in residues)


def test_analyze_refuses_to_overwrite_results(tmp_path, capsys):
    assert run(capsys, "analyze", DATA / "1TIM.pdb.gz", "-o", tmp_path, "--jobs", "1")[0] == 0
    before = (tmp_path / "summary.csv").read_text()
    status, _, err = run(capsys, "analyze", DATA / "1UBQ.pdb.gz", "-o", tmp_path, "--jobs", "1")
    assert status == 1 and "--overwrite" in err and (tmp_path / "summary.csv").read_text() == before
    status, out, _ = run(capsys, "analyze", DATA / "1UBQ.pdb.gz", "-o", tmp_path, "--jobs", "1", "--overwrite")
    assert status == 0 and "76 residues" in out and (tmp_path / "summary.csv").read_text() != before
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporary files left


def test_compare_a_distant_homologue_by_structure_or_by_sequence(capsys):
    common = ("compare", DATA / "3PTB.pdb.gz", DATA / "3SGB.pdb.gz", "--chains", "A:E", "--steps", "4", "--depths",
              "2", "--core-cutoff", "3", "--json")
    reports = {}
    for pairing in ("auto", "alignment"):
        status, out, _ = run(capsys, *common, "--pairing", pairing)
        assert status == 0
        reports[pairing] = json.loads(out)
    assert reports["auto"]["pairing"] == "structure" and reports["alignment"]["pairing"] == "alignment"
    assert reports["auto"]["paired_tm_score"] > reports["alignment"]["paired_tm_score"] + 0.1
    assert reports["auto"]["tm_score"] == pytest.approx(0.602, abs=0.02)  # TM-align's (by structure)
    assert reports["auto"]["n_core"] > 2 * reports["alignment"]["n_core"]


@pytest.mark.parametrize(
    ("argv", "status", "message"),
    [
        (["analyze", "{tmp}", "-o", "{tmp}/out"], 1, "no structure files"),
        (["analyze", DATA / "1UBQ.pdb.gz", "-o", "{tmp}/out", "--fraction-step", "0"], 2, "must lie in [0.05, 30]"),
        (["analyze", DATA / "1UBQ.pdb.gz", "-o", "{tmp}/out", "--max-depth", "-2"], 2, "must lie in [0, 30]"),
        (["analyze", DATA / "1UBQ.pdb.gz", "-o", "{tmp}/out", "--jobs", "0"], 2, "must lie in [1, 4096]; got 0"),
        (["analyze", DATA / "1UBQ.pdb.gz"], 2, "required: -o/--output"),
        (["analyze", DATA / "1UBQ.pdb.gz", "-o", DATA / "1UBQ.pdb.gz"], 1, "not a folder"),
    ],
)
def test_analyze_bad_input(argv, status, message, tmp_path, capsys):
    expect_exit_status([str(a).replace("{tmp}", str(tmp_path)) for a in argv], status, message, capsys)


def expect_exit_status(argv: list, status: int, message: str, capsys) -> None:
    """``main(argv)`` ends with ``status`` (2: argparse's SystemExit) and one line naming the problem."""
    if status == 2:
        with pytest.raises(SystemExit) as exit_info:
            main([str(a) for a in argv])
        assert exit_info.value.code == 2
    else:
        assert main([str(a) for a in argv]) == status
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


# --------------------------------------------------------------------------- compare


def test_compare_two_copies_of_tim(capsys):
    status, out, _ = run(capsys, "compare", DATA / "1TIM.pdb.gz")  # chains A and B by default
    assert status == 0
    assert "chain A (247 residues) vs" in out and "chain B (247 residues)" in out
    assert "247 residue pairs by numbering" in out
    assert "TM-score" in out and "normalised by the length of the first chain, 247 residues" in out
    for label in ("Cα", "C^r at level J − 1", "C^r at level J − 4"):
        assert label in out


def test_compare_json_fields(capsys):
    status, out, _ = run(capsys, "compare", DATA / "1TIM.pdb.gz", "--chains", "B:A", "--json", "--steps", "4",
                         "--depths", "2")
    report = json.loads(out)
    assert status == 0
    for key in ("rms_all", "n_pairs", "rms_core", "n_core", "tm_score", "tm_score_b", "paired_tm_score"):
        assert key in report
    assert "tm_score_a" not in report  # one TM-score by the first chain, TM-align's: the one named tm_score
    assert report["n_pairs"] == 247 and 0 < report["rms_core"] < report["rms_all"] < 3
    assert 0.8 < report["paired_tm_score"] <= 1 and report["paired_tm_score_length"] == 247
    assert "normalised by the length of the first chain" in report["paired_tm_score_note"]
    assert "TM-align" in report["tm_score_note"] and report["tm_score"] >= report["paired_tm_score"] - 1e-4
    b, a = (next(s for s in read_structure(DATA / "1TIM.pdb.gz").segments if s.chain == c) for c in "BA")
    judge = tmtools.tm_align(b.ca, a.ca, b.sequence, a.sequence)  # TM-align itself
    assert report["tm_score"] == pytest.approx(judge.tm_norm_chain1, abs=0.02)
    assert report["tm_score_b"] == pytest.approx(judge.tm_norm_chain2, abs=0.02)
    assert [(f["points"], f["every"], f["start"]) for f in report["fits"]] == (
        [("CA", 1, 1)] + [("CA", 4, s) for s in range(1, 5)] + [("C^r", 1, 1)] + [("C^r", 4, s) for s in range(1, 5)]
    )
    assert all(f["rms_core"] >= report["rms_core"] - 1e-4 for f in report["fits"])


def test_compare_two_entries_by_alignment_with_a_user_core(capsys):
    status, out, _ = run(capsys, "compare", DATA / "1TIM.pdb.gz", DATA / "8TIM.pdb.gz", "--chains", "A:A",
                         "--core", "10-100,150,200-240", "--json")
    report = json.loads(out)
    assert status == 0 and report["pairing"] == "alignment" and report["n_pairs"] == 247
    assert report["n_core"] == 91 + 1 + 41 and report["core_rule"] == "residues given by the user"


@pytest.mark.parametrize(("first", "second"), [("1UBQ", "3PTB"), ("1FKJ", "1UBQ"), ("1AYE", "1TIM"),
                                              ("1L2Y", "1UBQ"), ("2BEG", "1BPI"), ("1BPI", "4HHB")])
def test_compare_never_fails_on_unrelated_chains(first, second, capsys):
    files = [next(DATA.glob(f"{name}.*")) for name in (first, second)]
    status, out, err = run(capsys, "compare", *files, "--steps", "4", "--depths", "2", "--json")
    assert status == 0 and "Traceback" not in err
    report = json.loads(out)
    assert not report["same_fold"] and max(report["tm_score"], report["tm_score_b"]) < 0.5
    assert 3 <= report["n_aligned"] <= min(report["length_a"], report["length_b"])
    assert report["rms_aligned"] > 0 and 0 <= report["identity"] < 0.5


def test_compare_reports_the_match_by_either_chain(capsys):
    status, out, _ = run(capsys, "compare", DATA / "1UBQ.pdb.gz", DATA / "3PTB.pdb.gz", "--steps", "4", "--depths", "2")
    assert status == 0
    match = re.search(r"structural match: TM-score (\S+) \(normalised by the first chain, 76 residues\), (\S+) \(by the "
                      r"second, 223\); (\d+) aligned pairs, rms (\S+) Å, sequence identity (\S+)%", out)
    assert match, out
    tm_a, tm_b = float(match[1]), float(match[2])
    assert tm_a == pytest.approx(0.367, abs=0.03) and tm_b < tm_a  # TM-align: 0.367 by ubiquitin
    assert "different folds (TM-score < 0.5)" in out


def test_compare_without_a_core_set_gives_the_match_and_no_fits(capsys):
    argv = ["compare", DATA / "1UBQ.pdb.gz", DATA / "3PTB.pdb.gz", "--core-cutoff", "0.01"]
    status, out, _ = run(capsys, *argv)
    assert status == 0 and "too few for the fits on fewer data" in out and "fits on fewer data, each" not in out
    status, out, _ = run(capsys, *argv, "--json")
    report = json.loads(out)
    assert status == 0 and report["fits"] == [] and report["rms_core"] is None and report["n_core"] < 3


def test_compare_of_one_fold_says_so(capsys):
    status, out, _ = run(capsys, "compare", DATA / "3PTB.pdb.gz", DATA / "3SGB.pdb.gz", "--chains", "A:E", "--json",
                         "--steps", "4", "--depths", "2")
    report = json.loads(out)
    assert status == 0 and report["same_fold"] and report["tm_score"] == pytest.approx(0.602, abs=0.02)
    assert report["n_aligned"] > 150 and report["identity"] < 0.3  # TM-align: 0.602, 168 pairs


@pytest.mark.parametrize(
    ("argv", "status", "message"),
    [
        (["compare", DATA / "1UBQ.pdb.gz"], 1, "has one protein chain"),
        (["compare", DATA / "1TIM.pdb.gz", "--chains", "A:Z"], 1, "no protein chain 'Z'"),
        (["compare", DATA / "1TIM.pdb.gz", "--chains", "AB"], 2, "expected two chain ids"),
        (["compare", DATA / "1TIM.pdb.gz", "--core", "900-950"], 1, "no residue '900-950'"),
        (["compare", DATA / "1TIM.pdb.gz", "--core", "5-6"], 1, "core set has 2 pair(s)"),
        (["compare", DATA / "nothing.pdb"], 1, "no such file"),
    ],
)
def test_compare_bad_input(argv, status, message, capsys):
    expect_exit_status(argv, status, message, capsys)


# ----------------------------------------------------------------------- hostile inputs


def test_analyze_exits_1_when_every_file_was_skipped(tmp_path, capsys):
    (tmp_path / "in").mkdir()
    shutil.copy(DATA / "1BNA.pdb.gz", tmp_path / "in")  # DNA only
    (tmp_path / "in" / "junk.pdb").write_text("not a structure\n")
    status, _, err = run(capsys, "analyze", tmp_path / "in", "-o", tmp_path / "out", "--jobs", "1")
    assert status == 1 and "no file could be analysed: all 2 were skipped" in err
    assert len(read_csv(tmp_path / "out" / "skipped.csv")) == 2  # the reasons are written all the same


def test_analyze_into_a_folder_it_cannot_write(tmp_path, capsys):
    status, _, err = run(capsys, "analyze", DATA / "1UBQ.pdb.gz", "-o", "/proc", "--jobs", "1")
    assert status == 1 and err.startswith("ribbonwave: error: /proc: cannot write in the folder")
    assert "Traceback" not in err


def test_analyze_writes_through_no_planted_link(tmp_path, capsys):
    """Outputs replaced with --overwrite that are links to another file: the link is replaced,
    the file it pointed to is untouched; the outputs are written in a private folder first."""
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "victim.txt"
    victim.write_text("precious\n")
    for name in ("residues.csv", "summary.csv", "skipped.csv", "fig7.png"):
        (out / name).symlink_to(victim)
    status, _, _ = run(capsys, "analyze", DATA / "1UBQ.pdb.gz", "-o", out, "--overwrite", "--jobs", "1")
    assert status == 0 and victim.read_text() == "precious\n"
    assert all((out / name).is_file() and not (out / name).is_symlink() for name in ("residues.csv", "fig7.png"))
    assert sorted(p.name for p in out.iterdir()) == ["fig7.png", "residues.csv", "skipped.csv", "summary.csv"]


def test_entry_names_that_look_like_formulas_stay_text(tmp_path, capsys):
    import gzip

    (tmp_path / "in").mkdir()
    text = gzip.decompress((DATA / "1UBQ.pdb.gz").read_bytes()).decode()
    (tmp_path / "in" / "crafted.pdb").write_text(text.replace("02-JAN-87   1UBQ", "02-JAN-87   =1+2", 1))
    (tmp_path / "in" / "@SUM.pdb").write_text("garbage\n")
    status, _, _ = run(capsys, "analyze", tmp_path / "in", "-o", tmp_path / "out", "--jobs", "1")
    assert status == 0
    rows = read_csv(tmp_path / "out" / "residues.csv")
    assert {row["entry"] for row in rows} == {"'=1+2"}
    skipped = read_csv(tmp_path / "out" / "skipped.csv")
    assert skipped[0]["file"].endswith("@SUM.pdb") and not skipped[0]["reason"][:1] in "=+-@"


def _descendants(pid: int) -> set[int]:
    children: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    found, todo = set(), [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.add(child)
            todo.append(child)
    return found


def _running(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_killing_analyze_leaves_no_worker_and_the_next_run_cleans_up(tmp_path):
    import signal
    import subprocess
    import sys
    import time

    (tmp_path / "in").mkdir()
    for k in range(40):
        shutil.copy(DATA / "1TIM.pdb.gz", tmp_path / "in" / f"tim{k:02}.pdb.gz")
    out = tmp_path / "out"
    command = [sys.executable, "-m", "app", "analyze", str(tmp_path / "in"), "-o", str(out), "--jobs", "2"]
    child = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    workers: set[int] = set()
    while time.monotonic() < deadline and len(workers) < 3:  # the forkserver and two workers
        workers = _descendants(child.pid)
        time.sleep(0.05)
    time.sleep(1.0)  # at work
    assert child.poll() is None and len(workers) >= 3
    child.send_signal(signal.SIGKILL)
    child.wait()
    deadline = time.monotonic() + 10
    while time.monotonic() < deadline and any(_running(pid) for pid in workers):
        time.sleep(0.1)
    assert not any(_running(pid) for pid in workers)
    assert [p.name for p in out.iterdir()] and not (out / "residues.csv").exists()  # only the staging folder
    (tmp_path / "in2").mkdir()
    shutil.copy(DATA / "1UBQ.pdb.gz", tmp_path / "in2")
    assert main(["analyze", str(tmp_path / "in2"), "-o", str(out), "--jobs", "1"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["fig7.png", "residues.csv", "skipped.csv", "summary.csv"]


def _listening_ports() -> set[int]:
    ports = set()
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] == "0A":  # LISTEN
                ports.add(int(fields[1].rsplit(":", 1)[1], 16))
    return ports


def test_the_local_cluster_is_private(tmp_path, capsys):
    """``--scheduler`` alone: TLS with a certificate of this run, on 127.0.0.1, no HTTP server
    (no dashboard on 8787, no worker metrics); a client without the credentials cannot use it (#16)."""
    import contextlib

    import dask
    from dask.distributed import Client, LocalCluster

    from app.cli.batch import _local_client

    before = _listening_ports()
    with contextlib.ExitStack() as stack:
        client = _local_client(stack, LocalCluster, Client, 2, dask)
        cluster = client.cluster
        assert cluster.scheduler_address.startswith("tls://127.0.0.1:")
        workers = cluster.scheduler.workers.values()
        comms = {int(address.rsplit(":", 1)[1]) for address in
                 [cluster.scheduler_address, *(w.address for w in workers), *(w.nanny for w in workers)]}
        assert _listening_ports() - before == comms  # only the TLS comms: no HTTP endpoint at all
        with pytest.raises((OSError, TypeError, TimeoutError)):
            Client(cluster.scheduler_address, timeout=3)  # no credentials, no tasks
        assert client.submit(sum, [1, 2]).result() == 3
    status, out, _ = run(capsys, "analyze", DATA / "1UBQ.pdb.gz", "-o", tmp_path / "out", "--scheduler")
    assert status == 0 and "analysed 1 file(s)" in out


@pytest.mark.parametrize("address", ["http://127.0.0.1:8786", "tcp://127.0.0.1", "tcp://:8786", "tls://127.0.0.1:1",
                                     "tcp://127.0.0.1:99999"])
def test_a_scheduler_address_is_checked(address, tmp_path, capsys):
    status, _, err = run(capsys, "analyze", DATA / "1UBQ.pdb.gz", "-o", tmp_path / "out", "--scheduler", address)
    assert status == 1 and "expected tcp://HOST:PORT" in err and "Traceback" not in err


@pytest.mark.parametrize("reply, message", [(b"HTTP/1.1 400 Bad Request\r\n\r\n", "is not a Dask scheduler"),
                                            (None, "does not greet like a Dask scheduler")])
def test_a_server_that_is_not_a_scheduler_fails_within_the_timeout(reply, message, tmp_path, capsys, monkeypatch):
    import threading
    import time

    monkeypatch.setattr("app.cli.batch.DASK_TIMEOUT", 1.0)
    server = socket.create_server(("127.0.0.1", 0))
    held = []

    def serve() -> None:
        connection, _ = server.accept()
        held.append(connection)
        if reply is not None:
            connection.sendall(reply)

    threading.Thread(target=serve, daemon=True).start()
    start = time.monotonic()
    status, _, err = run(capsys, "analyze", DATA / "1UBQ.pdb.gz", "-o", tmp_path / "out", "--scheduler",
                         f"tcp://127.0.0.1:{server.getsockname()[1]}")
    assert status == 1 and message in err and time.monotonic() - start < 5
    server.close()
    for connection in held:
        connection.close()


def test_analyze_reads_and_names_files_whose_names_are_not_utf8(tmp_path, capsys):
    """A file name of Latin-1 bytes (ub\\xe9.pdb.gz) gave a UnicodeEncodeError at the first row
    (#37); it is analysed and named in UTF-8 outputs, its odd byte escaped, and so is a bad one."""
    folder = tmp_path / "in"
    folder.mkdir()
    shutil.copy(DATA / "1UBQ.pdb.gz", os.fsdecode(bytes(folder) + b"/ub\xe9.pdb.gz"))
    Path(os.fsdecode(bytes(folder) + b"/bad\xe9.pdb")).write_text("not a structure\n")
    (folder / "\x1b[2Jworse.pdb").write_text("not a structure\n")  # a name that would clear the terminal
    status, _, err = run(capsys, "analyze", folder, "-o", tmp_path / "out", "--jobs", "1")
    assert status == 0 and "Traceback" not in err and "\x1b" not in err and "skipped" in err
    assert "\\x1b[2Jworse.pdb" in err
    rows = (tmp_path / "out" / "residues.csv").read_text(encoding="utf-8").splitlines()
    assert len(rows) == 77 and rows[1].startswith(f"{folder}/ub\\udce9.pdb.gz,1UBQ,A,")
    assert "bad\\udce9.pdb" in (tmp_path / "out" / "skipped.csv").read_text(encoding="utf-8")
