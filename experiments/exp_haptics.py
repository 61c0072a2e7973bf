#!/usr/bin/python3
"""Haptic forces on a replayed stroke, every back-end: force versus time and versus depth.

The shipped recording experiments/haptics_stroke.csv (a session that `sandbench interactive
--device replay:... --record` wrote for flat_stroke.toml: press in 1 cm, pull 10 cm along the
diagonal, lift) is replayed through the real servo loop on each back-end, in a window under
xvfb-run, and each run records its own session. The figures plot the force the servo sent at
every tick; the table gives the per-tick force change (what the hand feels as clicks), the
force in steady contact and the passivity observer's final energy from the stats JSON.

As a measurement tool:  exp_haptics.py --measure 5 [--sandbench B] [--set key=value ...]
prints the medians over 5 runs per back-end.
"""
import json
import math
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import sbrun

# The back-ends compared; a new back-end is added here and nowhere else.
BACKENDS = ("grid", "tin")
RECORDING = sbrun.ROOT / "experiments" / "haptics_stroke.csv"
SCENE = sbrun.DIAGONAL_SCENE
FORCE_HEADER = ["t", "fx", "fy", "fz", "penetration_m"]
TRAJECTORY_HEADER = ["t", "x", "y", "z", "buttons"]


def read_tables(path):
    """The tables of a session file: {header tuple: [[floats], ...]} (non-numeric cells skipped)."""
    tables, header = {}, None
    for line in Path(path).read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        cells = [c.strip() for c in line.split(",")]
        try:
            row = [float(c) for c in cells]
        except ValueError:
            header = tuple(cells)
            tables.setdefault(header, [])
            continue
        if header is not None:
            tables[header].append(row)
    return tables


def replay_duration(path):
    t = read_tables(path)[tuple(TRAJECTORY_HEADER)]
    return t[-1][0] - t[0][0]


def replay(sandbench, backend, workdir, overrides=(), recording=None, reuse=False):
    """One interactive replay run; returns (stats dict, numpy arrays of the recorded session).
    reuse: keep a complete earlier run in workdir (the session and stats files are each written
    whole or not at all, the stats last)."""
    import numpy as np
    recording = recording or RECORDING
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    session, stats = workdir / f"{backend}_session.csv", workdir / f"{backend}_stats.json"
    if not (reuse and session.exists() and stats.exists()):
        _run_interactive(sandbench, backend, recording, session, stats, overrides)
    tables = read_tables(session)
    traj = np.array(tables[tuple(TRAJECTORY_HEADER)])
    force = np.array(tables[tuple(FORCE_HEADER)])
    return json.loads(stats.read_text()), {"t": force[:, 0], "f": force[:, 1:4], "depth": force[:, 4],
                                           "z": traj[:, 3], "xy": traj[:, 1:3]}


def _run_interactive(sandbench, backend, recording, session, stats, overrides):
    frames = int(math.ceil((replay_duration(recording) + 1.0) * 60))
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1024x768x24", str(sandbench), "interactive", str(SCENE),
           "--backend", backend, "--device", f"replay:{recording}", "--frames", str(frames),
           "--record", str(session), "--stats", str(stats), "--size", "640", "400"]
    for o in overrides:
        cmd += ["--set", o]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr}")


def steady_mask(rec):
    """Ticks of steady contact: the tool at its deepest (within 0.1 mm) and moving, the first and last
    0.2 s of that stretch left out (the press-in and the lift)."""
    import numpy as np
    z, t = rec["z"], rec["t"]
    bottom = z <= z.min() + 1e-4
    if not bottom.any():
        return bottom
    t0, t1 = t[bottom].min() + 0.2, t[bottom].max() - 0.2
    return bottom & (t >= t0) & (t <= t1)


def metrics(stats, rec):
    import numpy as np
    f = rec["f"]
    step = np.linalg.norm(np.diff(f, axis=0), axis=1)
    mag = np.linalg.norm(f, axis=1)
    steady = steady_mask(rec)
    contact = rec["depth"] > 0
    dfz = np.diff(f[:, 2])[contact[1:] & contact[:-1]]
    return {
        "force_max_n": float(mag.max()),
        "step_p99": float(np.percentile(step, 99)),
        "step_p999": float(np.percentile(step, 99.9)),
        "step_max": float(step.max()),
        "dfz_std_contact": float(dfz.std()) if dfz.size else 0.0,
        "steady_force_n": float(np.median(mag[steady])) if steady.any() else 0.0,
        "steady_force_mean_n": float(np.mean(mag[steady])) if steady.any() else 0.0,
        "passivity_energy_j": float(stats.get("passivity.energy_j", float("nan"))),
        "servo_hz": float(stats["servo_hz"]),
        "tick_us_p99": float(stats["tick_us.p99"]),
        "missed_deadlines": float(stats["missed_deadlines"]),
    }


COLUMNS = [("force_max_n", "force max N"), ("steady_force_n", "steady force median N"),
           ("steady_force_mean_n", "steady force mean N"), ("step_p99", "step p99 N"), ("step_p999", "step p99.9 N"),
           ("step_max", "step max N"), ("dfz_std_contact", "std dfz in contact N"),
           ("passivity_energy_j", "observer energy J"), ("servo_hz", "servo Hz"), ("tick_us_p99", "tick p99 us"),
           ("missed_deadlines", "missed")]


def run(ctx):
    import matplotlib.pyplot as plt
    import numpy as np

    if shutil.which("xvfb-run") is None:
        return {"skipped": "xvfb-run is not installed (`make deps`)"}
    workdir = ctx.runs / "haptics"
    # Real-time replays run on this machine whatever the engine; reused only from this binary.
    what = ["haptics replay", RECORDING, SCENE, *BACKENDS]
    current = ctx.is_current(workdir, what)
    runs = {}
    for b in BACKENDS:
        sbrun.progress(f"  haptics: replaying {RECORDING.name} on {b}")
        runs[b] = replay(ctx.sandbench, b, workdir, reuse=current)
    ctx.mark_current(workdir, what)

    with open(SCENE, "rb") as f:
        stiffness = min(float(tomllib.load(f).get("material", {}).get("stiffness_n_per_m", 800.0)), 2000.0)
    fig, axes = plt.subplots(len(BACKENDS), 1, figsize=(9, 2.6 * len(BACKENDS)), sharex=True, squeeze=False)
    for ax, b in zip(axes[:, 0], BACKENDS):
        rec = runs[b][1]
        ax.plot(rec["t"], stiffness * rec["depth"], lw=0.5, color="0.6", label="k d (the model's push, unrendered)")
        ax.plot(rec["t"], np.linalg.norm(rec["f"], axis=1), lw=0.8, label="|F| sent")
        ax.plot(rec["t"], rec["f"][:, 2], lw=0.6, label="Fz sent")
        ax.set_title(b, fontsize=9)
        ax.set_ylabel("force, N")
        ax.legend(fontsize=8, loc="upper right")
    axes[-1, 0].set_xlabel("servo time, s")
    axes[-1, 0].set_xlim(0.0, replay_duration(RECORDING) + 0.3)  # the last pose is held afterwards
    png_time = ctx.figure(fig, "haptics_force_vs_time")

    fig, ax = plt.subplots(figsize=(6, 4))
    for b in BACKENDS:
        rec = runs[b][1]
        ax.plot(1e3 * rec["depth"], rec["f"][:, 2], ".", ms=1.5, alpha=0.5, label=b)
    ax.set_xlabel("penetration d (mean depth of the tool bottom under the sand), mm")
    ax.set_ylabel("Fz, N")
    ax.legend(markerscale=6)
    png_depth = ctx.figure(fig, "haptics_force_vs_depth")

    rows = []
    for b in BACKENDS:
        m = metrics(*runs[b])
        rows.append([b] + [m[k] for k, _ in COLUMNS])
    md = ctx.table("haptics", ["back-end"] + [name for _, name in COLUMNS], rows)
    summary, per_backend = {}, {}
    for b, row in zip(BACKENDS, rows):
        m = per_backend[b] = dict(zip([k for k, _ in COLUMNS], row[1:]))
        summary[b] = {"haptic force quality": f"per-tick step p99 {m['step_p99']:.3g} N, steady {m['steady_force_n']:.2g} N"}
        if "fps" in runs[b][0]:
            summary[b]["interactive frame rate"] = f"{runs[b][0]['fps']:.0f} fps (xvfb)"
    return {"skipped": "", "png_time": png_time, "png_depth": png_depth, "table": md, "metrics": per_backend,
            "summary": summary}


def measure(sandbench, n, overrides, backends):
    """Medians over n runs per back-end, printed as a Markdown table."""
    import numpy as np
    with tempfile.TemporaryDirectory() as tmp:
        rows = []
        for b in backends:
            ms = []
            for i in range(n):
                ms.append(metrics(*replay(sandbench, b, Path(tmp) / f"{b}{i}", overrides)))
                sbrun.progress(f"{b} run {i + 1}/{n}: " + ", ".join(f"{k}={v:.4g}" for k, v in ms[-1].items()))
            rows.append((b, {k: float(np.median([m[k] for m in ms])) for k, _ in COLUMNS},
                         max(m["passivity_energy_j"] for m in ms)))
    print("| back-end | " + " | ".join(name for _, name in COLUMNS) + " | observer max over runs J |")
    print("|---" * (len(COLUMNS) + 2) + "|")
    for b, med, emax in rows:
        print(f"| {b} | " + " | ".join(f"{med[k]:.4g}" for k, _ in COLUMNS) + f" | {emax:.4g} |")


if __name__ == "__main__":
    if "--measure" in sys.argv:
        import argparse
        ap = argparse.ArgumentParser()
        ap.add_argument("--measure", type=int, required=True, help="runs per back-end")
        ap.add_argument("--sandbench", default=str(sbrun.ROOT / "build/release/harness/sandbench"))
        ap.add_argument("--set", action="append", default=[], help="scene override for every run")
        ap.add_argument("--backends", nargs="*", default=list(BACKENDS))
        ap.add_argument("--recording", default=str(RECORDING))
        a = ap.parse_args()
        sbrun.env_ok()
        RECORDING = Path(a.recording)
        measure(a.sandbench, a.measure, a.set, a.backends)
    else:
        sbrun.main(run)
