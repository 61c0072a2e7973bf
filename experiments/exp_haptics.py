#!/usr/bin/python3
"""Haptic forces on a replayed stroke, every back-end: force versus time and versus depth.

The shipped recording experiments/haptics_stroke.csv (a session that `sandbench interactive
--device replay:... --record` wrote for flat_stroke.toml: press in 1 cm, pull 10 cm along the
diagonal, lift) is replayed through the real servo loop on each back-end, in a window under
xvfb-run, and each run records its own session. The figures plot the force the servo sent at
every tick beside the force model's at the same pose; the table gives the per-tick force
change (what the hand feels as clicks), how far the force sent strays from the model's (p50,
p99, max) and how much later it reaches a contact's held force (onset lag), the force in
steady contact and the passivity observer's final energy from the stats JSON.

As a measurement tool:  exp_haptics.py --measure 5 [--sandbench B] [--set key=value ...]
prints the medians over 5 runs per back-end.
As a judge of rendering fidelity:  exp_haptics.py --judge [--sandbench B] [--out DIR]
replays smooth trajectories (haptics_trajectory.py: plunges peaking at 0.2 m/s, strokes at
several headings and speeds) with several tools, on every back-end, with the shipped settings,
with the force-rate limit off, and with the blend off too, and prints one row per run.
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
FORCE_HEADER = ["t", "fx", "fy", "fz", "penetration_m", "model_fx", "model_fy", "model_fz", "contact_fraction",
                "model_vx", "model_vy", "model_vz"]
# Sessions recorded before the model's contact fraction and velocity were, and before its force was.
FORCE_HEADER_WITHOUT_CONTACT = FORCE_HEADER[:8]
FORCE_HEADER_WITHOUT_MODEL = FORCE_HEADER[:5]
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


def replay(sandbench, backend, workdir, overrides=(), recording=None, reuse=False, scene=SCENE):
    """One interactive replay run; returns (stats dict, numpy arrays of the recorded session).
    reuse: keep a complete earlier run in workdir (the session and stats files are each written
    whole or not at all, the stats last)."""
    import numpy as np
    recording = recording or RECORDING
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    session, stats = workdir / f"{backend}_session.csv", workdir / f"{backend}_stats.json"
    if not (reuse and session.exists() and stats.exists()):
        _run_interactive(sandbench, backend, recording, session, stats, overrides, scene)
    return json.loads(stats.read_text()), read_session(session)


def read_session(session):
    """The recorded arrays: t, f (sent), model (the model's force at the same pose), depth, contact and
    velocity (the model's d, c and v on the newest patch: force_model.hpp), z, xy; a column the session
    lacks (older files) is NaN."""
    import numpy as np
    tables = read_tables(session)
    traj = np.array(tables[tuple(TRAJECTORY_HEADER)])
    header = next(h for h in (FORCE_HEADER, FORCE_HEADER_WITHOUT_CONTACT, FORCE_HEADER_WITHOUT_MODEL)
                  if tuple(h) in tables)
    force = np.array(tables[tuple(header)])
    force = np.hstack([force, np.full((len(force), len(FORCE_HEADER) - len(header)), np.nan)])
    return {"t": force[:, 0], "f": force[:, 1:4], "model": force[:, 5:8], "depth": force[:, 4],
            "contact": force[:, 8], "velocity": force[:, 9:12], "z": traj[:, 3], "xy": traj[:, 1:3]}


def _run_interactive(sandbench, backend, recording, session, stats, overrides, scene=SCENE):
    frames = int(math.ceil((replay_duration(recording) + 1.0) * FRAMES_PER_S))
    run_interactive(sandbench, scene, backend, recording, stats, overrides, frames, session=session)


def run_interactive(sandbench, scene, backend, recording, stats, overrides=(), frames=200, size=(640, 400),
                    session=None):
    """One `sandbench interactive` run replaying RECORDING in a window of SIZE (width, height) under xvfb-run
    (its screen at least 1024 x 768 and the window's size): FRAMES frames, the stats JSON to STATS and, when
    SESSION is given, the session recorded there. Raises with the command's stderr when it fails."""
    width, height = size
    screen = f"-screen 0 {max(width, 1024)}x{max(height, 768)}x24"
    cmd = ["xvfb-run", "-a", "-s", screen, str(sandbench), "interactive", str(scene), "--backend", backend,
           "--device", f"replay:{recording}", "--frames", str(frames), "--stats", str(stats),
           "--size", str(width), str(height)]
    if session is not None:
        cmd += ["--record", str(session)]
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


def onset_lag_ms(t, model, sent, window_s=0.3, held_s=0.1, quiet_s=0.05, level=0.9):
    """The largest onset lag over the run, ms, as the servo's OnsetLag (common/haptics/onset_lag.hpp) computes
    it: for each contact onset (model force non-zero after quiet_s without), the held force is the model's mean
    over the window's last held_s; the lag is when the force sent first reaches level times it minus when the
    model first did. NaN when no onset was long enough."""
    import numpy as np
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1e-3
    lags, i, n, quiet = [], 0, len(t), 0.0
    while i < n:
        if model[i] <= 0.0:
            quiet += dt
            i += 1
            continue
        if quiet < quiet_s:
            i += 1
            continue
        j = i
        while j < n and model[j] > 0.0 and t[j] - t[i] < window_s - 0.5 * dt:
            j += 1
        m, s, tt = model[i:j], sent[i:j], t[i:j]
        held_n = int(round(held_s / dt))
        if len(m) >= 2 * held_n:
            target = level * m[-held_n:].mean()
            first = lambda x: tt[np.argmax(x >= target)] if (x >= target).any() else tt[-1] + dt
            lags.append(1e3 * (first(s) - first(m)))
        quiet = 0.0
        i = j
    return max(lags) if lags else float("nan")


def fidelity(stats, rec):
    """How the force sent compares with the model's at the same pose: |difference| p50, p99, max (the model's
    force passed through the device's force limit first) and the onset lag."""
    import numpy as np
    f, model = rec["f"], rec["model"]
    if np.isnan(model).all():
        nan = float("nan")
        return {"error_p50": nan, "error_p99": nan, "error_max": nan, "onset_lag_ms": nan}
    mag = np.linalg.norm(model, axis=1)
    limit = float(stats.get("force_limit_n", np.inf))
    scale = np.where(mag > limit, limit / np.maximum(mag, 1e-300), 1.0)
    model = model * scale[:, None]
    err = np.linalg.norm(f - model, axis=1)
    return {"error_p50": float(np.percentile(err, 50)), "error_p99": float(np.percentile(err, 99)),
            "error_max": float(err.max()),
            "onset_lag_ms": onset_lag_ms(rec["t"], np.linalg.norm(model, axis=1), np.linalg.norm(f, axis=1))}


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
        **fidelity(stats, rec),
        "passivity_energy_j": float(stats.get("passivity.energy_j", float("nan"))),
        "servo_hz": float(stats["servo_hz"]),
        "tick_us_p99": float(stats["tick_us.p99"]),
        "missed_deadlines": float(stats["missed_deadlines"]),
    }


COLUMNS = [("force_max_n", "force max N"), ("steady_force_n", "steady force median N"),
           ("steady_force_mean_n", "steady force mean N"), ("step_p99", "step p99 N"), ("step_p999", "step p99.9 N"),
           ("step_max", "step max N"), ("dfz_std_contact", "std dfz in contact N"),
           ("error_p50", "sent - model p50 N"), ("error_p99", "sent - model p99 N"), ("error_max", "sent - model max N"),
           ("onset_lag_ms", "onset lag ms"),
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
        ax.plot(rec["t"], stiffness * rec["depth"], lw=0.5, color="0.75", label="k d on the newest patch")
        ax.plot(rec["t"], np.linalg.norm(rec["model"], axis=1), lw=1.6, color="0.2", ls=(0, (4, 2)),
                label="|F| of the model at the same pose")
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


# The judged motions (haptics_trajectory.py): (name, tool overrides, trajectory keyword arguments). Plunges 3 mm
# above to 10 mm into the sand, peaking at 0.2 m/s (0.122 s) or slower; strokes of 0.1 m at three headings and
# three speeds; the scene's disk, a box and a sphere-capped disk.
JUDGED = [
    ("disk 45deg 1.5s", [], {"heading_deg": 45.0, "stroke_s": 1.5}),
    ("disk 0deg 0.8s", [], {"heading_deg": 0.0, "stroke_s": 0.8}),
    ("box 0deg 0.8s", ["tool.shape=box", "tool.size_m=[0.04, 0.02]"], {"heading_deg": 0.0, "stroke_s": 0.8}),
    ("disk 120deg 2.5s", [], {"heading_deg": 120.0, "stroke_s": 2.5, "plunge_s": 0.3}),
    ("sphere 120deg 2.5s", ["tool.profile=sphere_cap"], {"heading_deg": 120.0, "stroke_s": 2.5}),
]
CONFIGS = [("shipped", []), ("rate limit off", ["haptics.max_force_rate_n_per_s=0"]),
           ("model itself", ["haptics.max_force_rate_n_per_s=0", "haptics.blend_ms=0"])]
JUDGED_BACKENDS = ("grid", "tin", "sparse")
# Frames drawn per second of motion: the window's frames end a run, at most 60 a second. A slower machine may
# draw fewer (--frames-per-s) to keep runs short; judge() says when a run ended before its motion.
FRAMES_PER_S = 60


def held_force(rec, kwargs):
    """Mean |F| sent over the last 0.1 s of the hold after the plunge."""
    import numpy as np
    plunge = kwargs.get("plunge_s", 0.122)
    end = 0.2 + plunge + kwargs.get("hold_s", 0.4)
    sel = (rec["t"] >= end - 0.1) & (rec["t"] < end)
    return float(np.linalg.norm(rec["f"][sel], axis=1).mean()) if sel.any() else float("nan")


def judge(sandbench, out, backends, names=None):
    """One run per judged motion, back-end and configuration; prints a Markdown row per run. Every figure comes
    from the recorded session over the motion's own duration (the stats' percentiles also count the ticks after
    it, which depend on how long the window took to draw its frames). A session without the model's force (an
    older binary) is compared with the 'model itself' run's force sent at the same servo time."""
    import numpy as np
    import haptics_trajectory as ht
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    cols = ["motion", "back-end", "settings", "step max N", "step p99.9 N", "sent - model p50 N", "p99 N", "max N",
            "onset lag ms", "held |F| N", "rate-limited ticks", "tick p99 us", "missed"]
    print("| " + " | ".join(cols) + " |")
    print("|---" * len(cols) + "|")
    for name, tool, kwargs in JUDGED:
        if names and name not in names:
            continue
        traj = out / (name.replace(" ", "_") + ".csv")
        ht.write(traj, ht.trajectory(**kwargs))
        for b in backends:
            runs = {}
            for cfg, sets in CONFIGS:
                wd = out / name.replace(" ", "_") / b / cfg.replace(" ", "_")
                sbrun.progress(f"  judge: {name} on {b}, {cfg}")
                runs[cfg] = replay(sandbench, b, wd, overrides=tool + sets, recording=traj, reuse=True)
            duration = replay_duration(traj)
            ref = runs["model itself"][1]
            for cfg, _ in CONFIGS:
                st, rec = runs[cfg]
                if st["duration_s"] < duration:
                    sbrun.progress(f"  judge: the {cfg} run ended {duration - st['duration_s']:.2f} s before the motion")
                keep = rec["t"] <= duration
                rec = {k: v[keep] for k, v in rec.items()}
                step = np.linalg.norm(np.diff(rec["f"], axis=0), axis=1)
                if np.isnan(rec["model"]).all():  # the model's force from the unrendered run at the same time
                    rec["model"] = np.stack([np.interp(rec["t"], ref["t"], ref["f"][:, k]) for k in range(3)], axis=1)
                fid = fidelity(st, rec)
                row = [name, b, cfg, step.max(), np.percentile(step, 99.9), fid["error_p50"], fid["error_p99"],
                       fid["error_max"], fid["onset_lag_ms"], held_force(rec, kwargs), st["ticks_rate_limited"],
                       st["tick_us.p99"], st["missed_deadlines"]]
                print("| " + " | ".join(v if isinstance(v, str) else f"{v:.4g}" for v in row) + " |", flush=True)


if __name__ == "__main__":
    if "--judge" in sys.argv:
        import argparse
        ap = argparse.ArgumentParser()
        ap.add_argument("--judge", action="store_true", required=True)
        ap.add_argument("--sandbench", default=str(sbrun.ROOT / "build/release/harness/sandbench"))
        ap.add_argument("--out", required=True, help="folder for trajectories, sessions and stats (reused)")
        ap.add_argument("--backends", nargs="*", default=list(JUDGED_BACKENDS))
        ap.add_argument("--motions", nargs="*", help="names from JUDGED (default: all)")
        ap.add_argument("--frames-per-s", type=float, default=FRAMES_PER_S, help="frames per second of motion")
        a = ap.parse_args()
        sbrun.env_ok()
        if not 0 < a.frames_per_s <= 1000:
            print(f"--frames-per-s must be in (0, 1000] (got {a.frames_per_s})", file=sys.stderr)
            sys.exit(2)
        FRAMES_PER_S = a.frames_per_s
        judge(a.sandbench, a.out, a.backends, a.motions)
    elif "--measure" in sys.argv:
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
