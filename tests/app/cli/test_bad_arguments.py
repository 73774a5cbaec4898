"""Numeric options outside their sane range are usage errors (exit 2) that name the range,
raised before any work; output paths are checked before the work too (#16)."""

from pathlib import Path

import pytest

from app.main import main

DATA = Path(__file__).resolve().parents[2] / "data"
UBQ = str(DATA / "1UBQ.pdb.gz")


@pytest.mark.parametrize("argv, message", [
    (["curve", UBQ, "--level", "inf"], "argument --level: must lie in [0, 30]; got inf"),
    (["curve", UBQ, "--level", "nan"], "argument --level: must lie in [0, 30]; got nan"),
    (["edit", UBQ, "--chain", "A", "--level", "1e9", "--point", "1", "--move", "1,0,0", "-o", "x.pdb"],
     "argument --level: must lie in [0, 30]"),
    (["edit", UBQ, "--chain", "A", "--level", "3", "--point", "-1", "--move", "1,0,0", "-o", "x.pdb"],
     "argument --point: must lie in [0, 1e+07]"),
    ([UBQ, "--level", "-1"], "argument --level: must lie in [0, 30]; got -1"),
    (["analyze", UBQ, "-o", "out", "--fraction-step", "1e-9"], "argument --fraction-step: must lie in [0.05, 30]"),
    (["analyze", UBQ, "-o", "out", "--max-depth", "1e300"], "argument --max-depth: must lie in [0, 30]"),
    (["surface", UBQ, "--spacing", "0.01", "-o", "s.vtp"], "argument --spacing: must lie in [0.2, 5]; got 0.01"),
    (["surface", UBQ, "--probe", "1e6", "-o", "s.vtp"], "argument --probe: must lie in [0, 5]; got 1e6"),
    (["surface", UBQ, "--level", "40", "-o", "s.vtp"], "argument --level: must lie in [0, 10]"),
    (["surface", UBQ, "--contour", "inf", "-o", "s.vtp"], "argument --contour: must lie in [-50, 50]"),
    (["compare", UBQ, "--depths", "99"], "argument --depths: numbers must lie in [1, 16]; got '99'"),
    (["compare", UBQ, "--steps", "0,2"], "argument --steps: numbers must lie in [1, 1000]"),
    (["compare", UBQ, "--core-cutoff", "-1"], "argument --core-cutoff: must lie in [0.01, 50]"),
])
def test_out_of_range_options_are_usage_errors(argv, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        main(argv)
    err = capsys.readouterr().err
    assert exit_info.value.code == 2 and message in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []  # nothing was written


def test_output_folder_is_checked_before_the_input_is_read(capsys, tmp_path):
    out = tmp_path / "missing" / "dir" / "s.vtp"
    assert main(["surface", str(tmp_path / "no-such-input.pdb"), "-o", str(out)]) == 1
    assert capsys.readouterr().err == f"ribbonwave: error: {out}: no such folder {out.parent}\n"


@pytest.mark.parametrize("command", [
    ["surface", UBQ, "-o", "{out}"],
    ["index", UBQ, "-o", "{out}", "--overwrite"],
    ["index", UBQ, "-o", "{out}"],
    ["edit", UBQ, "--chain", "A", "--level", "3", "--point", "1", "--move", "1,0,0", "-o", "{out}", "--overwrite"],
    [UBQ, "--screenshot", "{out}", "--overwrite"],
])
def test_every_command_refuses_a_folder_as_its_output_file_before_any_work(command, capsys, tmp_path):
    out = tmp_path / "shot.png" if command[0] == UBQ else tmp_path / "out.vtp"
    out.mkdir()
    assert main([part.replace("{out}", str(out)) for part in command]) == 1
    assert capsys.readouterr().err == f"ribbonwave: error: {out}: is a folder\n"
    assert list(out.iterdir()) == []


@pytest.mark.parametrize("command", [["info", UBQ + ":A"], ["compare", UBQ + ":A", UBQ], ["curve", UBQ + ":A"],
                                     [UBQ + ":A", "--screenshot", "shot.png"]])
def test_a_chain_after_a_colon_is_pointed_to_the_file_and_the_options(command, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(command) == 1
    assert capsys.readouterr().err == (f"ribbonwave: error: {UBQ}:A: no such file (this command takes no chain "
                                       f"after a colon: give {UBQ}, and see --help for a chain option)\n")


def test_negative_residue_ranges_are_values_not_options(capsys):
    status = main(["compare", str(DATA / "3PTB.pdb.gz"), str(DATA / "1BMA.pdb.gz"), "--core", "-45--30"])
    assert status == 1 and "--core: no residue '-45--30' in chain" in capsys.readouterr().err  # read as a range
