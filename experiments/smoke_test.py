#!/usr/bin/python3
"""Smoke test of the reproduction (run by CTest): the driver on the tiny profile into a
temporary folder, stopped after a few runs and started again (it must finish only the rest);
every figure and table must appear and every table must hold numbers; a third start runs
nothing and writes the same bytes."""
import csv
import math
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests" / "sweeps"))
from sweep_checks import sidecars  # noqa: E402  {finished run: (sidecar mtime, key)}
from report import prose_words  # noqa: E402
WORD_BUDGET = 3300  # REPORT.md's prose (tests/report/report_test.py)
FIGURES = ["fig5_tin_shaded.png", "fig5_tin_wireframe.png", "fig6_grid_shaded.png", "fig5_6_side_by_side.png",
           "fig5_6_difference.png", "fig7_time_vs_size.png", "fig8_time_vs_trace.png", "fig9_elements_vs_trace.png",
           "memory.png", "drift.png", "alpha_flat.png", "accuracy_speed.png", "orientation.png", "settling.png",
           "pile_relax.png", "cascade.png"]
TABLES = ["fig7_time_vs_size", "fig8_time_vs_trace", "fig9_elements_vs_trace", "memory", "drift", "alpha_flat",
          "accuracy", "orientation_cases", "orientation_trench", "orientation_worst", "settling",
          "pile_relax", "pile_positions", "cascade", "bars"]
if shutil.which("xvfb-run"):  # the interactive replays run under it (skipped without)
    FIGURES.append("interactive_scaling.png")
    TABLES.append("interactive_scaling")


def main():
    sandbench = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        cmd = ["/usr/bin/python3", str(HERE / "reproduce.py"), "--sandbench", sandbench, "--results", tmp,
               "--profile", "tiny"]
        # Stopped once a few runs are done, then started again: it must finish only the rest.
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        while proc.poll() is None and len(sidecars(tmp)) < 4:
            time.sleep(0.1)
        proc.send_signal(signal.SIGTERM)
        proc.wait()
        before = sidecars(tmp)
        second = subprocess.run(cmd, check=True, capture_output=True, text=True)
        todo = re.findall(r"round 1: (\d+) runs to do", second.stderr)
        after = sidecars(tmp)
        if todo != [str(len(after) - len(before))] or any(after[n] != t for n, t in before.items()):
            sys.exit(f"a stopped reproduction with {len(before)} of {len(after)} runs done did not resume: "
                     f"the second start did {todo} runs\n{second.stderr[-3000:]}")
        out = Path(tmp)
        missing = [f for f in FIGURES if not (out / f).exists() or (out / f).stat().st_size == 0]
        missing += [f"{t}.{e}" for t in TABLES for e in ("md", "csv") if not (out / f"{t}.{e}").exists()]
        if missing:
            sys.exit(f"missing outputs: {missing}")
        for t in TABLES:
            with open(out / f"{t}.csv") as f:
                rows = list(csv.reader(f))
            numbers = [float(c) for r in rows[1:] for c in r if _is_number(c)]
            if len(rows) < 2 or not numbers or not all(math.isfinite(x) for x in numbers):
                sys.exit(f"table {t} holds no finite numbers: {rows}")
        report = (out / "REPORT.md").read_text()
        if not (out / "stability.md").exists():
            sys.exit("missing stability.md")
        for heading in ["## Abstract", "| back-end |", "Figure 7", "Figures 8 and 9", "Memory", "drift", "alpha_flat",
                        "Figures 5 and 6", "Accuracy", "any orientation", "Stability"]:
            if heading not in report:
                sys.exit(f"REPORT.md has no section for {heading}")
        words = prose_words(report)
        if words > WORD_BUDGET:
            sys.exit(f"REPORT.md has {words} words of prose, over the budget of {WORD_BUDGET}")
        # A third start runs nothing and rewrites every output with the same bytes (SVGs included).
        outputs = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
        third = subprocess.run(cmd, check=True, capture_output=True, text=True)
        if "runs to do" in third.stderr or sidecars(tmp) != after:
            sys.exit(f"the third start ran something again:\n{third.stderr[-3000:]}")
        changed = [n for n, b in outputs.items() if (out / n).read_bytes() != b]
        if changed:
            sys.exit(f"outputs rewritten with other bytes from the same runs: {changed}")
    print("1 passed, 0 failed")


def _is_number(c):
    try:
        float(c)
        return True
    except ValueError:
        return False


if __name__ == "__main__":
    main()
