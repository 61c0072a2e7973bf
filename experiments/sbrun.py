"""Shared helpers for the experiment scripts: declare sandbench runs and get their results,
read run files, fit exponents, write figures (PNG and SVG) and tables (Markdown and CSV).

Runs are declared with Context.run_many(label, [(scene, backend, name, overrides)]): the
declaration is the same whichever engine executes them (engines.py: `local`, a thread pool;
`slurm`, a job array). A finished run is reused only when its key matches: the binary's build
identity and the run's inputs (runstore.py), so results always come from the binary at hand.

Two ways to run: an experiment script on its own executes its missing runs at once (local
engine); the reproduction driver sets `defer`, so run_many raises MissingRuns for every run
not yet done, the driver collects them from all experiments, hands them to the engine in one
go and calls the experiments again to aggregate (see reproduce.py).
"""
import csv
import math
import os
import subprocess
import sys
from pathlib import Path

import engines
import runstore

ROOT = Path(__file__).resolve().parent.parent
SCENES = ROOT / "experiments" / "scenes"
DIAGONAL_SCENE = SCENES / "flat_stroke.toml"
# The paper's erosion rule, named by the experiments that reproduce its figures (5-9 and
# alpha_flat), so they keep the paper's model whatever the default rule is; the experiments
# that judge accuracy run both rules.
PAPER_RULE = 'erosion.rule="edge"'
# pile.toml refines its TIN by curvature where the sand has come to rest ([tin]); the runs that
# sweep or compare the TIN's own refinement switch that off with this override.
NO_CURVATURE = "tin.curvature_tolerance_m=0"
DOMAIN_SIDE = 0.70710678  # flat_stroke.toml: a square whose diagonal is 1 m

# Sizes per profile: "tiny" for the smoke test, "paper" for `make reproduce`,
# "full" for `make reproduce FULL=1`.
PROFILES = {
    "tiny": {"fig7_n": [300, 1000], "trace": [0.1, 0.3], "fig8_n": 1000, "memory_cells": [0.02, 0.01],
             "reference_cell": 0.005, "alpha": [0.0, 0.4, 4.0], "drift_repeat": 1,
             "settle_cells": [0.01, 0.005], "stability_cases": ["crossing", "utm_offset", "nan_value"],
             "cliffs": ["sides_4096", "angle_5"], "cliff_repeats": 1, "bar_repeats": 1},
    "paper": {"fig7_n": [1000, 2000, 4000, 6000, 8000, 10000], "trace": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8,
              0.9, 1.0], "fig8_n": 10000, "memory_cells": [0.02, 0.01, 0.005, 0.0025, 0.00125],
              "reference_cell": 0.000625, "alpha": [0.0, 0.1, 0.2, 0.4, 0.8, 1.6, 3.2, 6.4], "drift_repeat": 3,
              "settle_cells": [0.0025, 0.00125, 0.000625, 0.0003125]},
    "full": {"fig7_n": [1000, 2000, 4000, 6000, 8000, 10000, 30000, 100000, 300000, 1000000],
             "trace": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0], "fig8_n": 10000,
             "memory_cells": [0.02, 0.01, 0.005, 0.0025, 0.00125, 0.000625], "reference_cell": 0.0003125,
             "alpha": [0.0, 0.05, 0.1, 0.2, 0.4, 0.8, 1.6, 3.2, 6.4, 12.8], "drift_repeat": 10,
             "settle_cells": [0.0025, 0.00125, 0.000625, 0.0003125, 0.00015625]},
}


progress = engines.progress


class MissingRuns(Exception):
    """Raised by run_many in deferred mode: these runs must be executed first."""

    def __init__(self, specs):
        super().__init__(f"{len(specs)} runs to execute")
        self.specs = specs


class Context:
    """Where an experiment reads and writes, and how its runs are executed."""

    def __init__(self, sandbench, results, profile="paper", jobs=2, engine=None):
        self.sandbench = Path(sandbench)
        self.results = Path(results)
        self.runs = self.results / "runs"
        self.profile_name = profile
        self.profile = PROFILES[profile]
        self.engine = engine or engines.LocalEngine(jobs)
        self.defer = False  # set by the driver: collect missing runs instead of executing them
        self.results.mkdir(parents=True, exist_ok=True)
        self.runs.mkdir(parents=True, exist_ok=True)
        self.binary = runstore.binary_identity(self.sandbench)
        self.used = {}  # name -> sidecar of every run whose result was handed out

    def spec(self, scene, backend, name, overrides=(), check=True, timeout=None):
        return runstore.make_spec(self.sandbench, self.binary, self.runs, scene, backend, name, overrides, check,
                                  timeout)

    def run(self, scene, backend, name, overrides=()):
        """One sandbench run (reused when done by this binary with these inputs); its summary."""
        return self.run_many(name, [(scene, backend, name, overrides)])[0]

    def run_many(self, label, jobs, check=True, timeout=None):
        """Declares runs [(scene, backend, name, overrides)] and returns their summaries in order.
        With check=False a failing run is a result, not an error: each result is then
        {"exit": code (None: over `timeout` seconds), "stderr": its end, "summary": {} unless 0}."""
        specs = [self.spec(*job, check=check, timeout=timeout) for job in jobs]
        missing = [s for s in specs if not runstore.read_sidecar(s)]
        if missing and self.defer:
            raise MissingRuns(missing)
        if missing:
            progress(f"  {label}: {len(missing)} of {len(specs)} runs to do")
            self.engine.execute(missing, label)
        results = []
        for s in specs:
            side = runstore.read_sidecar(s)
            if side is None:
                raise RuntimeError(f"run {s['name']} left no result (see the messages above)")
            self.used[s["name"]] = side
            results.append(side["summary"] if check else side)
        return results

    def is_current(self, folder, what):
        """Whether FOLDER was made by this binary from WHAT (a list of strings and files), as
        recorded by mark_current: for outputs that are not run files (a `compare` folder)."""
        try:
            return (Path(folder) / ".identity").read_text() == self._identity_of(what)
        except OSError:
            return False

    def mark_current(self, folder, what):
        (Path(folder) / ".identity").write_text(self._identity_of(what))

    def _identity_of(self, what):
        parts = [self.binary["build_id"]]
        parts += [runstore.sha256_file(w) if isinstance(w, Path) else str(w) for w in what]
        return "\n".join(parts) + "\n"

    def sandbench_cmd(self, *args):
        proc = subprocess.run([str(self.sandbench), *map(str, args)], capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"sandbench {' '.join(map(str, args))} failed:\n{proc.stderr}")
        return proc.stdout

    def figure(self, fig, name):
        """Saves a matplotlib figure as results/NAME.png and .svg; returns the PNG's name. The
        same figure gives the same bytes (no date, fixed SVG ids: see env_ok)."""
        for ext in ("png", "svg"):
            tmp = self.results / f"{name}.tmp.{ext}"
            fig.savefig(tmp, dpi=120, bbox_inches="tight", metadata={"Date": None} if ext == "svg" else None)
            tmp.replace(self.results / f"{name}.{ext}")
        import matplotlib.pyplot as plt
        plt.close(fig)
        return f"{name}.png"

    def table(self, name, headers, rows):
        """Writes results/NAME.md and .csv; returns the Markdown text."""
        def cell(v):
            if isinstance(v, float):
                return f"{v:.4g}" if v != 0 and (abs(v) < 1e-3 or abs(v) >= 1e5) else f"{v:.4f}".rstrip("0").rstrip(".")
            return str(v)
        md = "| " + " | ".join(headers) + " |\n|" + "---|" * len(headers) + "\n"
        md += "".join("| " + " | ".join(cell(v) for v in row) + " |\n" for row in rows)
        (self.results / f"{name}.md").write_text(md)
        with open(self.results / f"{name}.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(headers)
            w.writerows(rows)
        return md


def write_scene(path, text):
    """A scene variant kept with the runs (a cluster's nodes must read it), rewritten only when its
    text changed (runs are keyed on their inputs); returns the path."""
    path = Path(path)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)
    return path


def slug(text):
    """A run-name part from a label: letters and digits kept, everything else '_'."""
    return "".join(c if c.isalnum() else "_" for c in text).strip("_")


def loglog_slope(xs, ys):
    """Least-squares exponent b of y = a x^b over the positive points (nan if fewer than 2)."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x > 0 and y > 0]
    if len(pts) < 2:
        return float("nan")
    n = len(pts)
    mx = sum(p[0] for p in pts) / n
    my = sum(p[1] for p in pts) / n
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    if sxx == 0:
        return float("nan")
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx


def diagonal_path(fraction, margin=0.03):
    """A stroke along the domain's diagonal, centred, `fraction` of the diagonal long, its ends
    kept `margin` metres inside the domain so the tool and its rim stay in (so 1.0 of the
    diagonal is really 0.915 of it; the run's own length is what the tables report)."""
    c = DOMAIN_SIDE / 2
    half = min(fraction * DOMAIN_SIDE / 2, c - margin)
    a, b = c - half, c + half
    return f"stroke.path_m=[[{a:.6f}, {a:.6f}], [{b:.6f}, {b:.6f}]]"


def trace_length(fraction, margin=0.03):
    """The real length of diagonal_path(fraction), as a fraction of the 1 m diagonal."""
    return 2 * min(fraction * DOMAIN_SIDE / 2, DOMAIN_SIDE / 2 - margin) * math.sqrt(2)


def grid_cell_for(n_nodes):
    """Grid cell size giving about n_nodes nodes on the diagonal scene's square domain."""
    per_side = max(2.0, math.sqrt(n_nodes))
    return DOMAIN_SIDE / (per_side - 1)


def read_h5(path):
    import h5py
    return h5py.File(path, "r")


def env_ok():
    try:
        import h5py  # noqa: F401
        import matplotlib
        import numpy  # noqa: F401
    except ImportError as e:
        sys.exit(f"experiments need Debian's python3-numpy, python3-matplotlib and python3-h5py on "
                 f"/usr/bin/python3 ({e}); run `make deps`")
    os.environ.setdefault("MPLBACKEND", "Agg")
    # SVG element ids are random unless salted: a fixed salt makes a figure's SVG the same
    # bytes every time, so regenerating results from cached runs leaves git status clean.
    matplotlib.rcParams["svg.hashsalt"] = "sandbench"


def main(run):
    """Command line of a single experiment script (experiments/exp_KEY.py): runs it and prints its
    report section."""
    import argparse
    import report
    ap = argparse.ArgumentParser()
    ap.add_argument("--sandbench", default=str(ROOT / "build/release/harness/sandbench"))
    ap.add_argument("--results", default=str(ROOT / "results"))
    ap.add_argument("--profile", default="paper", choices=PROFILES)
    a = ap.parse_args()
    env_ok()
    key = Path(sys.argv[0]).stem.removeprefix("exp_")
    print(report.render(key, run(Context(a.sandbench, a.results, a.profile))))
