"""Checks shared by the sweep tests: which runs are finished, and whether two results
folders agree apart from timings (tables, run files, summaries)."""
import csv
import json
import math
import re
from pathlib import Path

# A table column or summary key that holds a wall-clock measurement (or a quantity fitted to
# one), which differs from run to run: "tool s", "step ms p50", "time s", "time_s.total"...
TIMING = re.compile(r"(^|[\s_.])(s|ms)($|[\s_.])|time|per_s|step p50|settling", re.IGNORECASE)
# Tables measured in real time as a whole (the haptic and the interactive replays: where the
# stamps fall and how many steps run depend on how fast the threads ran), compared by shape
# only: headers, rows, first column.
REAL_TIME_TABLES = {"haptics.csv", "interactive_scaling.csv"}
# Tables with a row per measure, named in the given column (the bars: a step time, an RMSE, a
# memory...): a row whose measure is timed is compared by its columns up to that one only.
ROW_TIMED_TABLES = {"bars.csv": 1}


def sidecars(results):
    """{run name: (mtime_ns, key)} of the finished runs under RESULTS/runs."""
    runs = Path(results) / "runs"
    out = {}
    for p in runs.rglob("*.json"):
        if ".slurm" in p.parts or p.name.endswith(".tmp"):
            continue
        try:
            side = json.loads(p.read_text())
        except ValueError:
            continue
        if "key" in side:
            out[str(p.relative_to(runs).with_suffix(""))] = (p.stat().st_mtime_ns, side["key"])
    return out


def _read_csv(path):
    with open(path, newline="") as f:
        return list(csv.reader(f))


def compare_tables(a, b):
    """Every CSV table of folder A equals B's apart from timing columns; failures as text."""
    failures = []
    names = sorted(p.name for p in Path(a).glob("*.csv"))
    if not names:
        return [f"no tables in {a}"]
    if names != sorted(p.name for p in Path(b).glob("*.csv")):
        return [f"different tables: {names} and {sorted(p.name for p in Path(b).glob('*.csv'))}"]
    for name in names:
        ta, tb = _read_csv(Path(a) / name), _read_csv(Path(b) / name)
        if ta[0] != tb[0] or len(ta) != len(tb):
            failures.append(f"{name}: different headers or row counts")
            continue
        keep = [0] if name in REAL_TIME_TABLES else [i for i, h in enumerate(ta[0]) if not TIMING.search(h)]
        for ra, rb in zip(ta[1:], tb[1:]):
            label = ROW_TIMED_TABLES.get(name)
            row_keep = list(range(label + 1)) if label is not None and TIMING.search(ra[label]) else keep
            if [ra[i] for i in row_keep] != [rb[i] for i in row_keep]:
                failures.append(f"{name}: rows differ outside timing columns:\n  {ra}\n  {rb}")
    return failures


def _same(x, y):
    if isinstance(x, float) and isinstance(y, float) and math.isnan(x) and math.isnan(y):
        return True
    return x == y


def compare_run_files(a, b):
    """Every run of runs folder A has a run in B with the same sidecar key, summary (timings
    aside), final raster, final mesh and per-step records (timings aside)."""
    import h5py
    import numpy as np
    failures = []
    names_a, names_b = sidecars(Path(a).parent), sidecars(Path(b).parent)
    if sorted(names_a) != sorted(names_b):
        return [f"different runs: {sorted(set(names_a) ^ set(names_b))[:10]}"]
    for name in sorted(names_a):
        if names_a[name][1] != names_b[name][1]:
            failures.append(f"{name}: different run keys")
        sa = json.loads((Path(a) / f"{name}.json").read_text())
        sb = json.loads((Path(b) / f"{name}.json").read_text())
        if sa["exit"] != sb["exit"]:
            failures.append(f"{name}: exit {sa['exit']} and {sb['exit']}")
        diff = [k for k in set(sa["summary"]) | set(sb["summary"])
                if not TIMING.search(k) and not _same(sa["summary"].get(k), sb["summary"].get(k))]
        if diff:
            failures.append(f"{name}: summaries differ in {sorted(diff)}")
        if sa["exit"] != 0:
            continue
        with h5py.File(Path(a) / f"{name}.h5", "r") as fa, h5py.File(Path(b) / f"{name}.h5", "r") as fb:
            paths = ["final/raster", "final/mesh/vertices", "final/mesh/triangles"]
            paths += [f"steps/{k}" for k in fa["steps"] if not TIMING.search(k)]
            for p in paths:
                if not np.array_equal(fa[p][()], fb[p][()], equal_nan=fa[p].dtype.kind == "f"):
                    failures.append(f"{name}: {p} differs")
            for attr in ("commit", "build_id"):
                if fa.attrs.get(attr) != fb.attrs.get(attr):
                    failures.append(f"{name}: run files record different {attr}")
    return failures
