#!/usr/bin/python3
"""The reproduction driver: `make reproduce` runs it. Each experiment writes its figures
and tables into results/; run files go to results/runs/ (not committed) so an interrupted
reproduction resumes where it stopped."""
import argparse
import datetime
import platform
import subprocess
from pathlib import Path

import sbrun

EXPERIMENTS = ["scenes"]


def machine_header(sandbench):
    version = subprocess.run([str(sandbench), "--version"], capture_output=True, text=True).stdout.strip()
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return (f"- date: {datetime.date.today().isoformat()}\n- {version}\n- machine: {platform.machine()}, {cpu}, "
            f"{len(__import__('os').sched_getaffinity(0))} cores\n- system: {platform.platform()}\n")


def experiment_scenes(sandbench, results):
    """Every shipped scene on every back-end: the contract metrics side by side."""
    lines = ["| scene | backend | stamps | time_s.total | step_ms.p50 | memory_bytes | vertices | cells |"
             " volume_drift_rel | max_slope_excess_deg |", "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for scene in sorted(sbrun.SCENES.glob("*.toml")):
        for backend in ("tin", "grid"):
            sbrun.progress(f"scenes: {scene.stem} on {backend}")
            s = sbrun.run(sandbench, scene, backend, results / "runs" / "scenes" / f"{scene.stem}-{backend}.h5")
            lines.append(f"| {scene.stem} | {backend} | {s['stamps']} | {s['time_s.total']:.4f} | "
                         f"{s['step_ms.p50']:.3f} | {s['memory_bytes']} | {s['vertices']} | {s['cells']} | "
                         f"{s['volume_drift_rel']:.3e} | {s['max_slope_excess_deg']:.3f} |")
    table = "\n".join(lines) + "\n"
    (results / "scenes.md").write_text(table)
    return "## Shipped scenes on both back-ends\n\n" + table


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--sandbench", default=None)
    ap.add_argument("--results", default=str(sbrun.ROOT / "results"))
    ap.add_argument("--full", action="store_true", help="extend sizes (to 1e6 vertices)")
    args = ap.parse_args()
    sandbench = sbrun.sandbench_path(args.sandbench)
    results = Path(args.results)
    results.mkdir(parents=True, exist_ok=True)

    sections = [experiment_scenes(sandbench, results)]
    report = "# sandbench reproduction report\n\n" + machine_header(sandbench) + "\n" + "\n".join(sections)
    tmp = results / "REPORT.md.tmp"
    tmp.write_text(report)
    tmp.replace(results / "REPORT.md")
    sbrun.progress(f"wrote {results / 'REPORT.md'}")


if __name__ == "__main__":
    main()
