"""The benchmarks `make bench` runs, one after the other, each printing its figures beside its targets:

1. benchmarks/bench_real.py: perception + grounding on every real frame of every folder under
   ../shared/data/real that has objects.csv (the arbiter), rgb, depth and rgbd;
2. benchmarks/bench_perception.py --per-class 5: perception on rendered scenes, every noise preset
   (a regression check).

    .venv/bin/python benchmarks/run_all.py            # about 5-10 minutes on two cores
    .venv/bin/python benchmarks/run_all.py --quick    # bench_real --limit 3, bench_perception --quick
    .venv/bin/python benchmarks/run_all.py --json out/bench   # bench_real's figures to out/bench/bench_real.json

Each runs in a process of its own (bench_real holds itself to one core). Exit status: 0 when every benchmark
ran, else that of the first that failed. Without ../shared/data/real the real benchmark is skipped with a
message, and the rendered one still runs.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
REAL = ROOT.parent / "shared" / "data" / "real"


def commands(quick: bool, json_dir: Path | None) -> list[tuple[str, list[str]]]:
    """(title, argv) of each benchmark to run."""
    real = [sys.executable, str(HERE / "bench_real.py")] + (["--limit", "3"] if quick else [])
    if json_dir is not None:
        real += ["--json", str(json_dir / "bench_real.json")]
    rendered = [sys.executable, str(HERE / "bench_perception.py")] + (["--quick"] if quick else ["--per-class", "5"])
    out = []
    if REAL.is_dir() and any((p / "objects.csv").is_file() for p in REAL.iterdir()):
        out.append(("real frames (benchmarks/bench_real.py)", real))
    else:
        print(f"run_all: no real frames with objects.csv under {REAL}: bench_real skipped", flush=True)
    out.append(("rendered scenes (benchmarks/bench_perception.py)", rendered))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="a few frames and scenes only (a smoke test)")
    ap.add_argument("--json", type=Path, metavar="DIR", help="write bench_real's figures to DIR/bench_real.json")
    args = ap.parse_args(argv)
    status = 0
    for title, cmd in commands(args.quick, args.json):
        print(f"\n######## {title}: {' '.join(Path(c).name if i < 2 else c for i, c in enumerate(cmd))}", flush=True)
        t = time.perf_counter()
        rc = subprocess.run(cmd, cwd=ROOT).returncode
        print(f"######## {title}: exit {rc}, {time.perf_counter() - t:.0f} s", flush=True)
        status = status or rc
    return status


if __name__ == "__main__":
    sys.exit(main())
