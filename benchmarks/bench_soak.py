"""A day of editing: STEPS scripted steps through ``rw`` (moves at changing levels, every
fifth an undo, as in the kill -9 tests) in a real editor window, printing per 1,000 steps the
process's resident memory (VmRSS), its growth since the start and the size of the
crash-recovery journal.

Usage: ``xvfb-run -a python benchmarks/bench_soak.py [--steps 50000] [STRUCTURE]`` (default
1UBQ from tests/data). The goal (#37): at 50,000 steps, no more than 500 MB above the start.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = """
import os, time
from pathlib import Path

def rss_mb():
    for line in open("/proc/self/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024

def journal_mb():
    return sum(p.stat().st_size for p in Path(os.environ["RW_STATE"]).glob("*.rwjournal")) / 2**20

steps, start, began = int(os.environ["RW_STEPS"]), rss_mb(), time.perf_counter()
n = len(rw.points())
print(f"{'steps':>7} {'RSS MB':>8} {'growth MB':>10} {'undo steps':>10} {'journal MB':>11} {'s/1000':>7}", flush=True)
last = began
for k in range(1, steps + 1):
    if k % 5 == 0:
        rw.undo()
    else:
        rw.level = 2 + k % 4
        rw.move(k % len(rw.points()), [0.3 * (-1) ** k, 0.2, -0.1])
    if k % 1000 == 0:
        now = time.perf_counter()
        print(f"{k:>7} {rss_mb():>8.0f} {rss_mb() - start:>10.0f} {rw.history()[1]:>10} {journal_mb():>11.1f} "
              f"{now - last:>7.1f}", flush=True)
        last = now
rw.quit(discard=True)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("structure", nargs="?", type=Path, default=ROOT / "tests" / "data" / "1UBQ.pdb.gz")
    parser.add_argument("--steps", type=int, default=50_000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        state = Path(folder) / "state"
        script = Path(folder) / "soak.py"
        script.write_text(SCRIPT)
        env = {**os.environ, "XDG_STATE_HOME": str(state), "RW_STATE": str(state / "ribbonwave"),
               "RW_STEPS": str(args.steps)}
        print(f"{args.structure.name}: {args.steps} steps (4 moves, then an undo)", flush=True)
        result = subprocess.run([sys.executable, "-m", "app", str(args.structure), "--script", str(script)],
                                cwd=ROOT, env=env, check=False)
    sys.exit(result.returncode)


if __name__ == "__main__":
    main()
