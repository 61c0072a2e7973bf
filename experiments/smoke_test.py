#!/usr/bin/python3
"""Smoke test of the reproduction (run by CTest): the driver on the tiny profile into a
temporary folder; every figure and table must appear and every table must hold numbers."""
import csv
import math
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
FIGURES = ["fig5_tin_shaded.png", "fig5_tin_wireframe.png", "fig6_grid_shaded.png", "fig5_6_side_by_side.png",
           "fig5_6_difference.png", "fig7_time_vs_size.png", "fig8_time_vs_trace.png", "fig9_elements_vs_trace.png",
           "memory.png", "drift.png", "alpha_flat.png", "accuracy_speed.png"]
TABLES = ["fig7_time_vs_size", "fig8_time_vs_trace", "fig9_elements_vs_trace", "memory", "drift", "alpha_flat",
          "accuracy"]


def main():
    sandbench = sys.argv[1]
    with tempfile.TemporaryDirectory() as tmp:
        cmd = ["/usr/bin/python3", str(HERE / "reproduce.py"), "--sandbench", sandbench, "--results", tmp,
               "--profile", "tiny"]
        subprocess.run(cmd, check=True)
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
        for heading in ["Figure 7", "Figure 8", "Figure 9", "Memory", "drift", "alpha_flat", "Figures 5 and 6",
                        "Accuracy", "Stability"]:
            if heading not in report:
                sys.exit(f"REPORT.md has no section for {heading}")
        # A second run resumes: nothing is run again.
        subprocess.run(cmd, check=True, capture_output=True)
    print("1 passed, 0 failed")


def _is_number(c):
    try:
        float(c)
        return True
    except ValueError:
        return False


if __name__ == "__main__":
    main()
