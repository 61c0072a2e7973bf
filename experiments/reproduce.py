#!/usr/bin/python3
"""The reproduction driver, run by `make reproduce`: every experiment at the paper's scale,
figures and tables into results/, and results/REPORT.md that compares each claim of the
paper with what we measured. Each experiment returns its values; report.py fills the
experiments' templates (experiments/report/) and assembles the report. Run files go to results/runs/ (not committed).

Each experiment declares its runs; the driver collects every run not yet done (by this
binary, with these inputs) from all experiments, hands them to one engine -- `local` (a pool
of --jobs on this machine) or `slurm` (one job array; see engines.py) -- and then lets the
experiments aggregate. Finished runs are reused, so an interrupted reproduction resumes and
a second one runs nothing."""
import argparse
import os
import platform
import resource
import subprocess
import time
from pathlib import Path

import engines
import report
import sbrun
import exp_accuracy
import exp_alpha_flat
import exp_bars
import exp_cascade
import exp_cliffs
import exp_drift
import exp_fig5_6
import exp_fig7
import exp_fig8_9
import exp_haptics
import exp_interactive_scaling
import exp_memory
import exp_orientation
import exp_particles
import exp_pile_positions
import exp_pile_relax
import exp_settling
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
    "orientation": exp_orientation,
    "pile_relax": exp_pile_relax,
    "pile_positions": exp_pile_positions,
    "particles": exp_particles,
    "settling": exp_settling,
    "cascade": exp_cascade,
    "stability": exp_stability,
    "cliffs": exp_cliffs,
    "bars": exp_bars,
    "haptics": exp_haptics,
    "interactive_scaling": exp_interactive_scaling,
}


def package_version(name):
    proc = subprocess.run(["dpkg-query", "-W", "-f=${Version}", name], capture_output=True, text=True)
    return proc.stdout.strip() or "?"


def machine_header(ctx):
    """The binary, the runs behind the numbers and the machine. Stable when nothing reran (no
    date of today, no commit of HEAD), so a second reproduction leaves REPORT.md as it was."""
    cpu, flags = "unknown", set()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name") and cpu == "unknown":
                cpu = line.split(":", 1)[1].strip()
            elif line.startswith("flags") and not flags:
                flags = set(line.split(":", 1)[1].split())
    except OSError:
        pass
    # The grid kernel's lanes follow the CPU (grid/erosion_kernel.hpp, has_avx512 / has_avx2), and
    # with them the grid's times: eight nodes at once with AVX-512, four with AVX2.
    lanes = ("AVX-512" if {"avx512f", "avx512vl", "avx512dq", "avx512bw"} <= flags
             else "AVX2" if "avx2" in flags else "SSE2")
    compiler = subprocess.run(["c++", "--version"], capture_output=True, text=True).stdout.splitlines()[0]
    libs = ", ".join(f"{n} {package_version(p)}" for n, p in
                     [("CGAL", "libcgal-dev"), ("Eigen", "libeigen3-dev"), ("HDF5", "libhdf5-dev"),
                      ("OSMesa", "libosmesa6-dev"), ("OpenVDB", "libopenvdb-dev")])
    sides = list(ctx.used.values())
    builds = sorted({s["binary"]["build_id"] for s in sides})
    commits = sorted({s["binary"]["commit"] for s in sides})
    dates = sorted(s["finished"] for s in sides)
    runs = (f"- runs: {len(sides)} sandbench runs, all by build {', '.join(builds)} (commit {', '.join(commits)}), "
            f"finished {dates[0]}..{dates[-1]}\n" if sides else "")
    return (f"- profile: {ctx.profile_name}\n"
            f"- binary: {ctx.binary['version']}; compiler {compiler}\n" + runs +
            f"- machine: {platform.machine()}, {cpu}, {len(os.sched_getaffinity(0))} cores, the grid kernel in {lanes} "
            f"lanes; {platform.platform()}\n"
            f"- libraries: {libs}\n")


def run_experiments(ctx, names):
    """Each experiment's values ({name: dict}, in the order of NAMES). Experiments raise
    MissingRuns until their runs are done; all missing runs of a round go to the engine together
    (one job array on SLURM)."""
    sections = {}
    for round_ in range(1, 10):
        missing = {}
        for i, name in enumerate(names, 1):
            if name in sections:
                continue
            start = time.monotonic()
            try:
                sections[name] = EXPERIMENTS[name].run(ctx)
                sbrun.progress(f"[{i}/{len(names)}] {name} done in {time.monotonic() - start:.0f} s")
            except sbrun.MissingRuns as m:
                for spec in m.specs:
                    missing.setdefault(spec["name"], spec)
                sbrun.progress(f"[{i}/{len(names)}] {name}: {len(m.specs)} runs to do")
        if not missing:
            return {n: sections[n] for n in names}
        sbrun.progress(f"round {round_}: {len(missing)} runs to do on the {ctx.engine.name} engine")
        ctx.engine.execute(list(missing.values()), "runs")
    raise RuntimeError("experiments still declare new runs after 9 rounds")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--sandbench", default=str(sbrun.ROOT / "build/release/harness/sandbench"))
    ap.add_argument("--results", default=str(sbrun.ROOT / "results"))
    ap.add_argument("--profile", default="paper", choices=sbrun.PROFILES)
    ap.add_argument("--full", action="store_true", help="the 'full' profile: sizes up to 1e6 vertices")
    ap.add_argument("--only", nargs="*", choices=EXPERIMENTS, help="run only these experiments")
    ap.add_argument("--jobs", type=int, default=2, help="local engine: runs at once")
    ap.add_argument("--engine", choices=["local", "slurm"], default="local",
                    help="local: a pool on this machine; slurm: a job array through sbatch")
    slurm = ap.add_argument_group("slurm engine (sbatch's defaults and SBATCH_* variables apply otherwise)")
    slurm.add_argument("--partition")
    slurm.add_argument("--account")
    slurm.add_argument("--time", help="time limit of one array task, sbatch syntax (e.g. 00:30:00)")
    slurm.add_argument("--mem", help="memory of one array task, sbatch syntax (e.g. 4G)")
    slurm.add_argument("--parallel", type=int, default=32, help="array tasks at once (the %%N throttle)")
    slurm.add_argument("--batch", type=int, default=1, help="runs per array task")
    slurm.add_argument("--sbatch-arg", action="append", default=[], help="one more sbatch argument (repeatable)")
    slurm.add_argument("--poll", type=float, default=5.0, help="seconds between squeue polls")
    args = ap.parse_args()
    sbrun.env_ok()
    engine = None
    if args.engine == "slurm":
        engine = engines.SlurmEngine(args.partition, args.account, args.time, args.mem, args.parallel, args.batch,
                                     args.sbatch_arg, args.poll)
    ctx = sbrun.Context(args.sandbench, args.results, "full" if args.full else args.profile, args.jobs, engine)
    ctx.defer = True
    names = args.only or list(EXPERIMENTS)
    sbrun.progress(f"reproduce: {len(names)} experiments, profile {ctx.profile_name}, {ctx.engine.name} engine, "
                   f"binary {ctx.binary['version']}")
    start = time.monotonic()
    values = run_experiments(ctx, names)
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
    sbrun.progress(f"reproduce: {time.monotonic() - start:.0f} s wall, {cpu.ru_utime + cpu.ru_stime:.0f} s CPU in "
                   f"processes run on this machine")
    if engine is not None:
        sbrun.progress(f"slurm: waited for job arrays {' '.join(engine.job_ids) or '(none: every run was done)'}")

    if args.only:  # a partial run prints its sections; only a full run writes REPORT.md
        print("\n".join(report.render(n, v) for n, v in values.items()))
        return
    tmp = ctx.results / "REPORT.md.tmp"
    tmp.write_text(report.assemble(machine_header(ctx), values))
    tmp.replace(ctx.results / "REPORT.md")
    sbrun.progress(f"wrote {ctx.results / 'REPORT.md'}")


if __name__ == "__main__":
    main()
