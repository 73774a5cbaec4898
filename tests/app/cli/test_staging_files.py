"""Files being written when a command was killed (kill -9 mid-write) are removed by the next
write into their folder, by any command; those of a running writer are left alone (#37)."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from app.main import main
from core.protein.writing import STAGING

DATA = Path(__file__).resolve().parents[2] / "data"
ROOT = Path(__file__).resolve().parents[3]


def _ended_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_the_next_write_removes_what_killed_writers_left(tmp_path: Path, capsys) -> None:
    left = [tmp_path / f".fitted.pdb{STAGING}{_ended_pid()}-x1y2.tmp", tmp_path / f".mesh.vtp{STAGING}{_ended_pid()}-q.vtp"]
    running = tmp_path / f".other.cif{STAGING}{os.getpid()}-abc.tmp"  # a writer still at work
    mine = tmp_path / "notes.staging-12.txt"  # a user's file of a similar name
    for path in [*left, running, mine]:
        path.write_bytes(b"partial")
    assert main(["edit", str(DATA / "1UBQ.pdb.gz"), "--chain", "A", "--level", "3", "--point", "2", "--move", "1,0,0",
                 "-o", str(tmp_path / "moved.pdb")]) == 0
    assert not any(path.exists() for path in left) and running.exists() and mine.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([running.name, mine.name, "moved.pdb"])


def test_kill_9_mid_write_then_any_command_cleans_up(tmp_path: Path, capsys) -> None:
    """A real kill: a session of writes (edit after edit into one folder) killed at random moments."""
    script = ("import sys\nfrom app.main import main\n"
              "for k in range(200):\n"
              f"    main(['edit', {str(DATA / '4YVS.cif.gz')!r}, '--chain', 'A', '--level', '4', '--point', '3',"
              f" '--move', '1,0,0', '-o', {str(tmp_path / 'moved.cif')!r}, '--overwrite'])\n")
    for delay in (1.3, 1.9, 2.6):
        child = subprocess.Popen([sys.executable, "-c", script], cwd=ROOT, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
        time.sleep(delay)
        os.kill(child.pid, signal.SIGKILL)
        child.wait()
    assert main(["edit", str(DATA / "1UBQ.pdb.gz"), "--chain", "A", "--level", "3", "--point", "2", "--move", "1,0,0",
                 "-o", str(tmp_path / "after.pdb")]) == 0
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
