"""lv3d's learner against Metagol itself on Metagol's own example files, unchanged, side by side.

    .venv/bin/python -m benchmarks.bench_metagol [--metagol ../shared/reference/metagol] [--limit 60]
        [--only grandparent,robots | --quick] [--json out/bench/bench_metagol.json]

--quick (what `make bench` runs) leaves out the files whose goals take seconds or reach the limit
(droplasts2, robots, robots2, son, sorter) and sets the limit to 10 s.

For every learning goal of every file of Metagol's examples/ folder (the goals ``lv3d mil`` learns:
those the file's directives run, else each learning goal clause), it runs Metagol (SWI-Prolog
consults the file; a directive's goal runs as the file loads, a goal clause is called after) and
``lv3d mil`` (lv3d.learn.task.run_task, the exact search), each under a time limit of --limit
seconds. Times are the CPU seconds of the learning goal in each process (running the goal, which
builds the examples, and the search; not the process start), so that a busy machine does not
blur them.

Columns: each side's time and result (the number of clauses, none: no program, or why it failed),
whether the programs are the same text, and whether they cover the same examples (each program
proved on the goal's positive and negative examples by lv3d's interpreter). The target (the
learner issue's): every goal Metagol solves within the limit (a program, or none when there is
none) gives an equivalent program, the same coverage, in at most 2x Metagol's time + 0.5 s.
Without Metagol's metagol.pl only lv3d's columns are filled; without its examples/ folder nothing runs.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

from lv3d.errors import InputError
from lv3d.learn import task as tasks
from lv3d.learn.engine import LearnError

ROOT = Path(__file__).resolve().parent.parent
SLOW = ("droplasts2", "robots", "robots2", "son", "sorter")  # goals of seconds, or reaching the limit
METAGOL = ROOT.parent / "shared" / "reference" / "metagol"

# Runs a Metagol example: consults FILE (Metagol itself loads from the file's own directive); a
# learning directive's goal is timed as it runs, a goal clause GOAL is called and timed after.
# Markers on standard output: BENCH-START <id> and BENCH-END <id> <cpu seconds> <status>.
DRIVER = r"""
:- dynamic bench_limit/1.
:- use_module(library(time)).
:- multifile user:term_expansion/2.
:- dynamic user:term_expansion/2.
bench_expansion(File) :-
    assertz((user:term_expansion((:- G), (:- bench_directive(Line, G))) :-
                prolog_load_context(source, File), \+ G = bench_directive(_, _),
                prolog_load_context(term_position, P), stream_position_data(line_count, P, Line))).
bench_directive(Line, G) :- format(atom(Id), 'directive at line ~w', [Line]), bench_run(Id, G).
bench_run(Id, G) :-
    bench_limit(T), format("BENCH-START ~w~n", [Id]), flush_output,
    statistics(cputime, C0),
    catch(( call_with_time_limit(T, G) -> S = done ; S = failed ), E,
          ( E == time_limit_exceeded -> S = timeout ; S = error )),
    statistics(cputime, C1), C is C1 - C0,
    format("~nBENCH-END ~w ~4f ~w~n", [Id, C, S]), flush_output.
bench_main :-
    current_prolog_flag(argv, [File, Goal, LimitA]), atom_number(LimitA, Limit),
    assertz(bench_limit(Limit)),
    file_directory_name(File, Dir), working_directory(_, Dir), file_base_name(File, Base),
    (   Goal == '' -> absolute_file_name(Base, Abs), bench_expansion(Abs), consult(Base)
    ;   consult(Base), atom_to_term(Goal, G, _), bench_run(Goal, G)
    ).
:- initialization(bench_main, main).
"""


def run_metagol(driver: Path, example: Path, goal: str, limit: float) -> dict[str, dict]:
    """{goal id: {"cpu": s, "status": done|failed|timeout|error, "clauses": [...]}} of one Metagol run."""
    args = ["swipl", "-q", str(driver), "--", str(example), goal, str(limit)]
    try:
        r = subprocess.run(args, capture_output=True, text=True, timeout=3 * limit + 30)
        out = r.stdout
    except subprocess.TimeoutExpired as e:
        out = e.stdout.decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
    runs, cur = {}, None
    for line in out.splitlines():
        if line.startswith("BENCH-START "):
            cur = line[len("BENCH-START "):].strip()
            runs[cur] = {"cpu": None, "status": "timeout", "clauses": []}
        elif line.startswith("BENCH-END ") and cur is not None:
            parts = line.split()
            runs[cur]["cpu"], runs[cur]["status"] = float(parts[-2]), parts[-1]
            cur = None
        elif cur is not None and line.strip().endswith(".") and not line.startswith("%"):
            runs[cur]["clauses"].append(line.strip())
    return runs


def coverage(example: Path, goal: str, clauses: list[str], limit: float) -> tuple[str | None, str]:
    """('<pos bits>/<neg bits>' of the clauses on the goal's examples (lv3d's interpreter), or None with why the
    check gave none: its exit status and the last line it wrote to stderr)."""
    import prolog as sources

    if not clauses:
        return None, "no clauses"
    with tempfile.NamedTemporaryFile("w", suffix=".pl", delete=False) as f:
        f.write("\n".join(clauses) + "\n")
        path = f.name
    try:
        r = subprocess.run([tasks.swipl(), "-q", str(sources.source("mil_main.pl")), "--", str(example),
                            f"[time_limit({limit})]", f"check:{path}", goal],
                           capture_output=True, text=True, timeout=3 * limit + 30)
    except subprocess.TimeoutExpired:
        return None, f"no answer within {3 * limit + 30:g} s"
    finally:
        Path(path).unlink(missing_ok=True)
    for line in r.stdout.splitlines():
        rec = line.split("\t")
        if rec[0] == "coverage":
            return f"{rec[1]}/{rec[2]}", ""
        if rec[0] == "failed":
            return None, " ".join(rec[1:])
    err = r.stderr.strip().splitlines()
    return None, f"exit {r.returncode}" + (f": {err[-1]}" if err else "")


def result_text(status: str | None, clauses) -> str:
    if status in ("done", "program"):
        return f"{len(clauses)} clauses" if clauses else "none"
    return {"failed": "none", "timeout": "time limit", "error": "error", None: "-"}.get(status, status)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--metagol", type=Path, default=METAGOL, help="Metagol's folder (metagol.pl, examples/)")
    ap.add_argument("--limit", type=float, default=60.0, help="seconds each side may take per goal")
    ap.add_argument("--only", default=None, help="comma-separated example names (without .pl)")
    ap.add_argument("--json", type=Path, default=None, help="write the rows here too")
    ap.add_argument("--quick", action="store_true", help="the quick files only, limit 10 s")
    a = ap.parse_args(argv)
    if a.quick:
        a.limit = min(a.limit, 10.0)
    examples_dir = a.metagol / "examples"
    if not examples_dir.is_dir():
        print(f"bench_metagol: no Metagol examples at {examples_dir}: skipped", flush=True)
        return 0
    have_metagol = (a.metagol / "metagol.pl").is_file()
    files = sorted(examples_dir.glob("*.pl"))
    if a.only:
        wanted = {n.strip() for n in a.only.split(",")}
        files = [f for f in files if f.stem in wanted]
    elif a.quick:
        files = [f for f in files if f.stem not in SLOW]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        driver = Path(tmp) / "bench_driver.pl"
        driver.write_text(DRIVER)
        for ex in files:
            try:
                run = tasks.run_task(ex, time_limit=a.limit)
            except (InputError, LearnError) as e:
                msg = e.problem if isinstance(e, InputError) else str(e)
                rows.append({"file": ex.name, "goal": "-", "ours": "refused", "ours_s": None, "why": msg,
                             "metagol": "-", "metagol_s": None, "same_text": None, "same_cov": None, "target": "-"})
                print(f"{ex.name}: refused: {msg}", flush=True)
                continue
            for g in run.goals:
                is_dir = g.name.startswith("directive at line")
                mg = {}
                if have_metagol:
                    runs = run_metagol(driver, ex, "" if is_dir else g.name, a.limit)
                    mg = runs.get(g.name, {"cpu": None, "status": "error", "clauses": []})
                ours_clauses = list(g.clauses or [])
                m_clauses = mg.get("clauses", [])
                m_status = mg.get("status")
                m_solved = m_status in ("done", "failed") and mg.get("cpu") is not None and mg["cpu"] <= a.limit
                same_text = (ours_clauses == m_clauses) if have_metagol and g.error is None else None
                goal_arg = "" if is_dir else g.name
                cov_o, why_o = coverage(ex, goal_arg, ours_clauses, a.limit) if ours_clauses else (None, "no program")
                cov_m, why_m = coverage(ex, goal_arg, m_clauses, a.limit) if m_clauses else (None, "no program")
                same_cov = None
                if have_metagol and g.error is None:
                    same_cov = cov_o == cov_m
                    if not same_cov:  # say what each check gave, so that a difference can be traced
                        print(f"{ex.name} {g.name}: coverage of lv3d's program {cov_o or why_o}, of Metagol's "
                              f"{cov_m or why_m}", flush=True)
                target = "-"
                if have_metagol and m_solved:
                    ok = bool(same_cov) and g.error is None and g.cpu_s <= 2 * mg["cpu"] + 0.5
                    target = "pass" if ok else "FAIL"
                row = {"file": ex.name, "goal": g.name, "metagol_s": mg.get("cpu"),
                       "metagol": result_text(m_status, m_clauses) if have_metagol else "-",
                       "ours_s": g.cpu_s, "ours": result_text("program" if g.clauses else
                                                              ("failed" if g.error is None else g.kind), ours_clauses),
                       "same_text": same_text, "same_cov": same_cov, "target": target,
                       "why": g.error, "coverage": cov_o}
                rows.append(row)
                print(f"{ex.name} {g.name}: metagol {row['metagol']} {row['metagol_s']}, lv3d {row['ours']} "
                      f"{row['ours_s']:.3f}, same text {same_text}, same coverage {same_cov}, {target}", flush=True)
    print()
    print("| file | goal | Metagol s | Metagol | lv3d s | lv3d | same program | same coverage | target (<= 2x + 0.5 s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        def s(v):
            return "-" if v is None else f"{v:.3f}"

        def yn(v):
            return "-" if v is None else ("yes" if v else "no")
        print(f"| {r['file']} | {r['goal']} | {s(r['metagol_s'])} | {r['metagol']} | {s(r['ours_s'])} | "
              f"{r['ours']} | {yn(r['same_text'])} | {yn(r['same_cov'])} | {r['target']} |")
    solved = [r for r in rows if r["target"] != "-"]
    passed = sum(r["target"] == "pass" for r in solved)
    print(f"\n{passed} of {len(solved)} goals that Metagol solves within {a.limit:g} s give the same coverage in at "
          f"most 2x its time + 0.5 s (target: all {len(solved)}); {sum(bool(r['same_text']) for r in rows)} of "
          f"{len(rows)} rows print the same program text")
    for r in rows:
        if r.get("why") and r["ours"] in ("refused",):
            print(f"  {r['file']}: {r['why']}")
    if a.json:
        a.json.parent.mkdir(parents=True, exist_ok=True)
        a.json.write_text(json.dumps(rows, indent=1))
    return 0 if passed == len(solved) else 1


if __name__ == "__main__":
    sys.exit(main())
