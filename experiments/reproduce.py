#!/usr/bin/python3
"""The reproduction driver, run by `make reproduce`: every experiment at the paper's scale,
figures and tables into results/, and results/REPORT.md that compares each claim of the
paper with what we measured. Run files go to results/runs/ (not committed); complete runs
are skipped, so an interrupted reproduction resumes and a second run is instant."""
import argparse
import datetime
import os
import platform
import subprocess
import time
from pathlib import Path

import sbrun
import exp_accuracy
import exp_alpha_flat
import exp_drift
import exp_fig5_6
import exp_fig7
import exp_fig8_9
import exp_haptics
import exp_memory
import exp_sparse
import exp_stability

EXPERIMENTS = {
    "fig5_6": exp_fig5_6,
    "fig7": exp_fig7,
    "fig8_9": exp_fig8_9,
    "memory": exp_memory,
    "sparse": exp_sparse,
    "drift": exp_drift,
    "alpha_flat": exp_alpha_flat,
    "accuracy": exp_accuracy,
    "stability": exp_stability,
    "haptics": exp_haptics,
}


def package_version(name):
    proc = subprocess.run(["dpkg-query", "-W", "-f=${Version}", name], capture_output=True, text=True)
    return proc.stdout.strip() or "?"


def machine_header(ctx):
    version = ctx.sandbench_cmd("--version").strip()
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    compiler = subprocess.run(["c++", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    libs = ", ".join(f"{n} {package_version(p)}" for n, p in
                     [("CGAL", "libcgal-dev"), ("Eigen", "libeigen3-dev"), ("HDF5", "libhdf5-dev"),
                      ("OSMesa", "libosmesa6-dev"), ("OpenVDB", "libopenvdb-dev")])
    return (f"- date: {datetime.date.today().isoformat()}; profile: {ctx.profile_name}\n"
            f"- {version}, built with {compiler}\n"
            f"- machine: {platform.machine()}, {cpu}, {len(os.sched_getaffinity(0))} cores; {platform.platform()}\n"
            f"- libraries: {libs}\n")


INTRO = """The paper's setup: a square terrain whose diagonal is 1 m, a disk tool (radius 2 cm, 32-gon,
1 cm deep) pulled along the diagonal, alpha_flat 0.4 degrees, critical angle 30 degrees. Both back-ends
receive the same stamp schedule (`experiments/scenes/flat_stroke.toml` with `--set` overrides). Times are
wall seconds summed over the whole stroke, as in the paper; this machine is shared, so compare ratios and
exponents rather than absolute times. The paper's machine was a Core 2 Duo at 1.8 GHz (2008).

TIN size N: the paper's TIN had N vertices before the stroke; ours gets them with `tin.initial_points = N`
(a jittered lattice on the flat surface). Left to itself our TIN starts from the 4 corners of a flat domain;
the grid is given the same number of nodes.
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--sandbench", default=str(sbrun.ROOT / "build/release/harness/sandbench"))
    ap.add_argument("--results", default=str(sbrun.ROOT / "results"))
    ap.add_argument("--profile", default="paper", choices=sbrun.PROFILES)
    ap.add_argument("--full", action="store_true", help="the 'full' profile: sizes up to 1e6 vertices")
    ap.add_argument("--only", nargs="*", choices=EXPERIMENTS, help="run only these experiments")
    args = ap.parse_args()
    sbrun.env_ok()
    ctx = sbrun.Context(args.sandbench, args.results, "full" if args.full else args.profile)

    sections = []
    names = args.only or list(EXPERIMENTS)
    for i, name in enumerate(names, 1):
        sbrun.progress(f"[{i}/{len(names)}] {name}")
        start = time.monotonic()
        sections.append(EXPERIMENTS[name].run(ctx))
        sbrun.progress(f"[{i}/{len(names)}] {name} done in {time.monotonic() - start:.0f} s")

    if args.only:  # a partial run prints its sections; only a full run writes REPORT.md
        print("\n".join(sections))
        return
    report = ("# sandbench: reproducing Purchart's TIN sand model\n\n" + machine_header(ctx) + "\n" + INTRO + "\n" +
              "\n".join(sections))
    tmp = ctx.results / "REPORT.md.tmp"
    tmp.write_text(report)
    tmp.replace(ctx.results / "REPORT.md")
    sbrun.progress(f"wrote {ctx.results / 'REPORT.md'}")


if __name__ == "__main__":
    main()
