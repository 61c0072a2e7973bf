#!/usr/bin/python3
"""Interactive scaling: frame rate, stamp-to-frame latency and simulation step against domain size, every
back-end, in a 1280 x 720 window under xvfb-run.

One plunge-and-stroke (haptics_trajectory.py: wait 3 mm above the sand, plunge 1 cm in, stroke 0.1 m along the
diagonal, lift), centred on the domain, is replayed through `sandbench interactive` on flat_stroke.toml's sand
over square domains of 1 m (cells of 10, 5, 2 and 1 mm: 1e4 to 1e6 grid nodes), of 0.25 and 2 m at 1 mm (what
grows with the domain at one cell size) and 2.0475 m at 0.5 mm (4096 x 4096 nodes); the TIN on the same domains,
its element count its vertex count at the end (the stats'). Each run
draws FRAMES frames and its --stats JSON gives every figure; the renderer is the stats' `gl_renderer`
(glGetString(GL_RENDERER)), "unknown" from a binary that does not write it. Beside the replays, `sandbench run`
strokes the same path at 5 and 1 mm: what its stamps touch and what they and their erosion cost, without a window.

The bars on the 1 m replay: grid and sparse at 1 mm at least 0.8 x their frame rate at 5 mm, a sim step
p95 within 1.5 x of the 5 mm run's and a stamp-to-frame p95 of at most 50 ms; the 4096 x 4096 grid at least 15 fps
and each stamp shown within 100 ms. The bars' cases run BAR_ROUNDS times in interleaved rounds (a ratio pairs the
runs of one round); a bar gives the rounds' median and range, and is met, missed, or straddled when some rounds
meet it and some do not. The table shows each case's first run. The tiny profile runs the smallest grid case only.

Where the 1 mm latency goes: "stamp to frame start" is a stamp's wait until the window takes it at the start of the
frame that shows it (the rest of its latency is that frame's drawing), and in the bars' rounds the 1 mm grid is
replayed once more without erosion (erosion.max_passes_per_step = 0): what the erosion after each stamp, on the
same two cores as the software renderer, adds to the latency.

One case by hand (the trajectory: haptics_trajectory.py TRAJ --centre 0.5 0.5 --wait-s 1.5 --hold-s 0.2 --stroke-s 1):
  xvfb-run -a -s '-screen 0 1280x768x24' sandbench interactive experiments/scenes/flat_stroke.toml --backend B
    --set 'domain.size_m=[1.0,1.0]' --set grid.cell_m=C --device replay:TRAJ --frames 200 --size 1280 720 --stats S
"""
import shutil

import exp_haptics
import haptics_trajectory
import sbrun

SCENE = sbrun.DIAGONAL_SCENE
BACKENDS = ("grid", "sparse", "tin")
LATTICE_BACKENDS = ("grid", "sparse")  # the back-ends whose size is set by grid.cell_m
WINDOW = (1280, 720)
FRAMES = 200
# The motion: the tool waits 1.5 s above the sand, so that the window is up before the first stamp (the first
# frame uploads the whole lattice, longest on the largest; a stamp during it waits for it); holds and stroke
# shorter than haptics_trajectory's defaults, so that 200 frames cover the 3.1 s of motion at the window's 60 Hz
# pacing.
MOTION = {"wait_s": 1.5, "hold_s": 0.2, "stroke_s": 1.0}
# (domain side m, grid cell m) per profile; the TIN runs once per side on the flat sand, and on dunes (a TIN
# grows with what the terrain holds, not with the domain) at each of DUNES_TOLERANCES on the 1 m square.
DOMAINS = {"tiny": [(1.0, 0.01)],
           "paper": [(1.0, 0.01), (1.0, 0.005), (1.0, 0.002), (1.0, 0.001), (0.25, 0.001), (2.0, 0.001),
                     (2.0475, 0.0005)]}
DUNES = ["terrain.kind=dunes", "terrain.wavelength_m=0.1"]
DUNES_TOLERANCES = {"tiny": [], "paper": [0.0004, 0.0002, 0.0001]}  # tin.tolerance_m
TINY_BACKENDS = ("grid",)
# The bars' cases: the 1 m replay at 5 and 1 mm, and the 4096 x 4096 grid.
COARSE, FINE, LARGE = (1.0, 0.005), (1.0, 0.001), (2.0475, 0.0005)
NEAR = 0.1  # a figure within 10 % of its bar is flagged
COST_REPEATS = 3
# The bars' cases are replayed this many times, in rounds (every bar case once a round), so that a bar's verdict
# says whether the runs' spread straddles it: on a shared 2-core machine one run flips a bar near its limit.
BAR_ROUNDS = 3
# Replayed in each round beside the bars' cases, with these overrides: the 1 mm grid without erosion.
NO_EROSION = (("grid", *FINE), ["erosion.max_passes_per_step=0"])

# (values key, table header, stats key)
COLUMNS = [("fps", "fps", "fps"), ("frame_p50", "frame ms p50", "frame_ms.p50"),
           ("frame_p99", "frame ms p99", "frame_ms.p99"),
           ("latency_p50", "stamp to frame ms p50", "stamp_to_frame_ms.p50"),
           ("latency_p95", "stamp to frame ms p95", "stamp_to_frame_ms.p95"),
           ("latency_max", "stamp to frame ms max", "stamp_to_frame_ms.max"),
           ("take_p95", "stamp to frame start ms p95", "stamp_to_take_ms.p95"),
           ("step_p50", "sim step ms p50", "sim.step_ms.p50"), ("step_p95", "sim step ms p95", "sim.step_ms.p95"),
           ("step_cpu_p95", "sim step CPU ms p95", "sim.step_cpu_ms.p95"),
           ("display_p50", "display ms p50", "display_ms.p50"), ("display_p95", "display ms p95", "display_ms.p95"), ("upload_p95", "upload ms p95", "upload_ms.p95"),
           ("stamps", "stamps", "sim.stamps"), ("steps", "sim steps", "sim.steps"),
           ("sim_cpu_s", "sim CPU s", "sim.step_cpu_s.total")]


def cases(profile_name):
    """(back-end, domain side m, resolution m) in table order: a grid's cell; the TIN's tin.tolerance_m on dunes,
    or None on the flat sand."""
    domains = DOMAINS.get(profile_name, DOMAINS["paper"])
    backends = TINY_BACKENDS if profile_name == "tiny" else BACKENDS
    out = []
    for b in backends:
        if b in LATTICE_BACKENDS:
            out += [(b, side, cell) for side, cell in domains]
        else:
            out += [(b, side, None) for side in dict.fromkeys(side for side, _ in domains)]
            out += [(b, 1.0, tol) for tol in DUNES_TOLERANCES.get(profile_name, DUNES_TOLERANCES["paper"])]
    return out


def on_dunes(case):
    return case[0] not in LATTICE_BACKENDS and case[2] is not None


def case_name(case):
    b, side, res = case
    if on_dunes(case):
        return f"{b}-{side:g}m-dunes-{res * 1e3:g}mm"
    return f"{b}-{side:g}m" + (f"-{res * 1e3:g}mm" if res is not None else "")


def overrides(case):
    _, side, res = case
    sets = [f"domain.size_m=[{side!r}, {side!r}]"]
    if on_dunes(case):
        return sets + DUNES + [f"tin.tolerance_m={res!r}"]
    return sets + ([f"grid.cell_m={res!r}"] if res is not None else [])


def trajectory_file(folder, side):
    """The replay for a domain of SIDE metres: the motion centred on it (written once, the same bytes each time)."""
    path = folder / f"stroke-{side:g}m.csv"
    rows = haptics_trajectory.trajectory(centre=(0.5 * side, 0.5 * side), **MOTION)
    tmp = path.with_suffix(".tmp")
    haptics_trajectory.write(tmp, rows)
    if path.exists() and path.read_bytes() == tmp.read_bytes():
        tmp.unlink()
    else:
        tmp.replace(path)
    return path


def figures(case, stats):
    """A case's row values from its stats JSON. Without a stamp there is no latency (the stats' percentile of
    nothing is 0): NaN."""
    # (stamp_to_frame_ms.max is absent from binaries older than the key: NaN.)
    row = {key: float(stats.get(name, float("nan"))) for key, _, name in COLUMNS}
    row["elements"] = int(stats["vertices"] if case[0] == "tin" else stats["cells"])
    if row["stamps"] == 0:
        row["latency_p50"] = row["latency_p95"] = row["latency_max"] = row["take_p95"] = float("nan")
    return row


def renderer_of(all_stats):
    names = sorted({str(s.get("gl_renderer", "unknown")) for s in all_stats}) or ["unknown"]
    return ", ".join(names)


def bar(label, backend, value, limit, at_least, unit=""):
    """One bar's line: met or missed, and flagged when the figure is within NEAR of the bar."""
    met = value >= limit if at_least else value <= limit
    near = limit > 0 and abs(value / limit - 1.0) < NEAR
    return {"bar": label, "backend": backend, "measured": f"{value:.3g}{unit}",
            "limit": f"{'>=' if at_least else '<='} {limit:g}{unit}",
            "verdict": ("met" if met else "missed") + (f" (within {NEAR:.0%})" if near else ""), "met": met}


def bar_over_rounds(label, backend, values, limit, at_least, unit=""):
    """A bar judged on each round's figure: met or missed when every round agrees, else straddled; the measured
    figure is the rounds' median and range."""
    import statistics
    lines = [bar(label, backend, v, limit, at_least, unit) for v in values]
    line = bar(label, backend, statistics.median(values), limit, at_least, unit)
    met = sum(x["met"] for x in lines)
    if len(values) > 1:
        line["measured"] += f" [{min(values):.3g}-{max(values):.3g}]"
        if 0 < met < len(values):
            line["verdict"] = f"straddled: met in {met} of {len(values)} runs"
    line["met"] = met == len(values)
    line["straddled"] = 0 < met < len(values)
    return line


def judge(rounds):
    """The bars against the runs ({case: [figures of each round]}) that the profile ran; a ratio pairs the runs
    of one round."""
    out = []
    for b in LATTICE_BACKENDS:
        coarse, fine = rounds.get((b, *COARSE)), rounds.get((b, *FINE))
        if coarse and fine:
            pairs = list(zip(coarse, fine))
            out.append(bar_over_rounds("fps 1 mm / 5 mm", b, [f["fps"] / c["fps"] for c, f in pairs], 0.8, True))
            out.append(bar_over_rounds("sim step p95 1 mm / 5 mm", b, [f["step_p95"] / c["step_p95"] for c, f in pairs],
                                       1.5, False))
            out.append(bar_over_rounds("stamp to frame p95 at 1 mm", b, [f["latency_p95"] for f in fine], 50, False,
                                       " ms"))
    large = rounds.get(("grid", *LARGE))
    if large:
        out.append(bar_over_rounds("fps at 4096 x 4096", "grid", [r["fps"] for r in large], 15, True))
        out.append(bar_over_rounds("stamp to frame, largest, at 4096 x 4096", "grid", [r["latency_max"] for r in large],
                                   100, False, " ms"))
    return out


def bars_table(bars):
    md = "| bar | back-end | measured | bar | verdict |\n|---|---|---|---|---|\n"
    return md + "".join(f"| {b['bar']} | {b['backend']} | {b['measured']} | {b['limit']} | {b['verdict']} |\n"
                        for b in bars)


def plot(ctx, rows, renderer):
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter
    plain = FuncFormatter(lambda y, _: f"{y:g}")
    some = FuncFormatter(lambda y, _: f"{y:g}" if f"{y:.0e}"[0] in "25" else "")  # minor ticks: 2 and 5 only
    panels = [("fps", "frames per second", [(15, "4096^2 bar")]),
              ("latency_p95", "stamp to frame p95, ms", [(50, "1 m bar"), (100, "4096^2 bar")]),
              ("step_p95", "sim step p95, ms", [])]
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for ax, (key, label, lines) in zip(axes, panels):
        for b in BACKENDS:
            for dunes in (False, True):
                pts = sorted((r["elements"], r[key]) for c, r in rows.items()
                             if c[0] == b and on_dunes(c) == dunes and r[key] > 0)
                if pts:
                    ax.plot(*zip(*pts), "s--" if dunes else "o-", label=b + (" (dunes)" if dunes else ""))
        for y, text in lines:
            ax.axhline(y, color="0.6", ls="--", lw=0.8)
            ax.annotate(text, (0.02, y), xycoords=("axes fraction", "data"), fontsize=7, color="0.4", va="bottom")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(plain)
        ax.yaxis.set_minor_formatter(some)
        ax.tick_params(axis="y", which="minor", labelsize=7)
        ax.set_xlabel("elements (grid nodes, TIN vertices)")
        ax.set_ylabel(label)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"{WINDOW[0]} x {WINDOW[1]} window under Xvfb, renderer: {renderer}", fontsize=9)
    fig.tight_layout()
    return ctx.figure(fig, "interactive_scaling")


def bar_cases(todo):
    """The cases the bars read, in table order."""
    return [c for c in todo if (c[0] in LATTICE_BACKENDS and c[1:] in (COARSE, FINE)) or c == ("grid", *LARGE)]


def run_cases(ctx, todo):
    """{case: [stats dict of each run]}: each case replayed once, the bars' cases BAR_ROUNDS times in rounds (the
    first round is every case's run), and the NO_EROSION run in each round (under the key "no erosion"); a run is
    reused when this binary already made it with these inputs (the stats file is written whole or not at all)."""
    import json
    folder = ctx.runs / "interactive_scaling" / "replays"
    folder.mkdir(parents=True, exist_ok=True)
    # Every profile's replays, so that the folder's identity does not depend on the profile.
    sides = dict.fromkeys(side for domains in DOMAINS.values() for side, _ in domains)
    trajectories = {side: trajectory_file(folder, side) for side in sides}
    what = ["interactive scaling", SCENE, FRAMES, WINDOW, *trajectories.values()]
    if not ctx.is_current(folder, what):
        for old in folder.glob("*.json"):
            old.unlink()
        ctx.mark_current(folder, what)
    out = {}
    no_erosion = [NO_EROSION[0]] if NO_EROSION[0] in todo else []
    runs = [(case, 0, False) for case in todo] + [(case, 0, True) for case in no_erosion]
    runs += [(case, i, diag) for i in range(1, BAR_ROUNDS) for case, diag in
             [(c, False) for c in bar_cases(todo)] + [(c, True) for c in no_erosion]]
    for case, i, diag in runs:
        name = case_name(case) + ("-no-erosion" if diag else "") + (f"-round{i + 1}" if i else "")
        stats = folder / f"{name}.json"
        if not stats.exists():
            sbrun.progress(f"  interactive_scaling: replaying on {name}")
            exp_haptics.run_interactive(ctx.sandbench, SCENE, case[0], trajectories[case[1]], stats,
                                        overrides(case) + (NO_EROSION[1] if diag else []), FRAMES, WINDOW)
        key = "no erosion" if diag else case
        out.setdefault(key, []).append(json.loads(stats.read_text()))
        if out[key][-1]["sim.stamps"] == 0:
            sbrun.progress(f"  interactive_scaling: no stamp on {name} (the run ended before the plunge)")
    return out


def stamp_costs(ctx, todo):
    """{back-end: {touched, step}}: what the stroke's stamps touch and what a stamp's step (the stamp and its
    erosion) costs at 1 mm over 5 mm, from `sandbench run` on the same stroke (no window, no servo), for the lattice
    back-ends the profile runs at both. The step is the median of COST_REPEATS runs' step p50 (the phases' totals
    are not used: at 5 mm the whole stroke takes a few ms, and a one-time cost of some ms lands in either phase)."""
    import statistics
    pairs = [b for b in LATTICE_BACKENDS if (b, *COARSE) in todo and (b, *FINE) in todo]
    c, half = 0.5 * COARSE[0], 0.05 / 2 ** 0.5  # the replay's stroke: 0.1 m along the diagonal, centred
    path = f"stroke.path_m=[[{c - half:.6f}, {c - half:.6f}], [{c + half:.6f}, {c + half:.6f}]]"
    keys = [(b, side, cell, i) for b in pairs for side, cell in (COARSE, FINE) for i in range(COST_REPEATS)]
    jobs = [(SCENE, b, f"interactive_scaling/{case_name((b, side, cell))}-{i}", overrides((b, side, cell)) + [path])
            for b, side, cell, i in keys]
    runs = dict(zip(keys, ctx.run_many("interactive_scaling", jobs)))

    def median(b, size, key):
        return statistics.median(runs[(b, *size, i)][key] for i in range(COST_REPEATS))
    return {b: {k: median(b, FINE, name) / median(b, COARSE, name) for k, name in
                [("touched", "elements_touched"), ("step", "step_ms.p50")]}
            for b in pairs}


def run(ctx):
    if shutil.which("xvfb-run") is None:
        return {"skipped": "xvfb-run is not installed (`make deps`)"}
    todo = cases(ctx.profile_name)
    costs = stamp_costs(ctx, todo)  # first: the driver runs them on its engine before the replays
    stats = run_cases(ctx, todo)
    no_erosion = [figures(NO_EROSION[0], s) for s in stats.pop("no erosion", [])]
    rounds = {c: [figures(c, s) for s in runs] for c, runs in stats.items()}
    return values(ctx, rounds, renderer_of(s for runs in stats.values() for s in runs), costs, no_erosion)


def order(case):
    """Table order: back-end, flat before dunes, then domain, coarse cells (tolerances) first."""
    b, side, res = case
    return BACKENDS.index(b), on_dunes(case), side, -(res or 0.0)


def values(ctx, rounds, renderer, costs=None, no_erosion=()):
    """The section's values from the runs ({case: [figures of each round]}), the stamps' costs (stamp_costs) and
    the NO_EROSION case's figures in each round: figure, table (each case's first run), bars (every round), summary
    cells, where the 1 mm grid's latency goes."""
    import statistics
    rows = {c: runs[0] for c, runs in rounds.items()}
    todo = sorted(rows, key=order)
    png = plot(ctx, rows, renderer)
    table_rows = [[b, "dunes" if on_dunes((b, side, res)) else "flat", side, res * 1e3 if res is not None else "",
                   rows[(b, side, res)]["elements"]] +
                  [rows[(b, side, res)][key] for key, _, _ in COLUMNS] for b, side, res in todo]
    md = ctx.table("interactive_scaling", ["back-end", "terrain", "domain m", "cell (TIN: tolerance) mm", "elements"] +
                   [header for _, header, _ in COLUMNS], table_rows)
    bars = judge(rounds)
    summary = {}
    for b in BACKENDS:  # the finest 1 m case of each back-end
        one_m = [c for c in todo if c[0] == b and c[1] == 1.0 and not on_dunes(c)]
        if one_m:
            r = rows[one_m[-1]]
            summary[b] = {"interactive frame rate": f"{r['fps']:.0f} fps at {r['elements']:.2g} "
                          f"{'vertices' if b == 'tin' else 'nodes'}, {WINDOW[0]}x{WINDOW[1]}"}
    # How many median frames a stamp waits to be shown (p95), over the runs that stamped.
    lags = [r["latency_p95"] / r["frame_p50"] for r in rows.values() if r["stamps"] > 0 and r["frame_p50"] > 0]
    # The step bar's ratio on the thread's CPU clock: what the steps cost without waiting for a core.
    cpu_ratio = {b: statistics.median(f["step_cpu_p95"] / c["step_cpu_p95"]
                                      for c, f in zip(rounds[(b, *COARSE)], rounds[(b, *FINE)]))
                 for b in LATTICE_BACKENDS if (b, *FINE) in rows and (b, *COARSE) in rows and
                 all(c["step_cpu_p95"] > 0 for c in rounds[(b, *COARSE)])}
    # The ratio's two sides (medians over the rounds): a cheaper 5 mm step raises it as a dearer 1 mm one does.
    cpu_steps = {b: {size: statistics.median(r["step_cpu_p95"] for r in rounds[(b, *cell)])
                     for size, cell in (("coarse", COARSE), ("fine", FINE))} for b in cpu_ratio}
    # Where the 1 mm grid's latency p95 goes (medians and ranges over the rounds): the wait for the frame that
    # shows a stamp, and what the erosion after the stamps adds (the same replay without erosion).
    fine = rounds.get(NO_EROSION[0], [])

    def spread(xs):
        return {"median": statistics.median(xs), "lo": min(xs), "hi": max(xs)}
    coarse = rounds.get(("grid", *COARSE), [])
    latency = ({"with": spread([r["latency_p95"] for r in fine]), "take": spread([r["take_p95"] for r in fine]),
                "without": spread([r["latency_p95"] for r in no_erosion]),
                "sim_cpu_s": spread([r["sim_cpu_s"] for r in fine]),
                "sim_cpu_s_coarse": spread([r["sim_cpu_s"] for r in coarse])} if fine and coarse and no_erosion else {})
    # The step at one cell size (the bars' fine one) on domains of several sizes: what grows with the domain.
    same_cell = {b: [(c[1], rows[c]["step_cpu_p95"]) for c in todo if c[0] == b and c[2] == FINE[1]]
                 for b in LATTICE_BACKENDS}
    same_cell = {b: v for b, v in same_cell.items() if len(v) > 1}
    tin = [rows[c] for c in todo if c[0] == "tin" and c[1] == 1.0 and not on_dunes(c)]
    dunes = [rows[c] for c in todo if on_dunes(c)]
    return {"skipped": "", "png": png, "table": md, "renderer": renderer, "window": f"{WINDOW[0]} x {WINDOW[1]}",
            "lag_lo": min(lags, default=float("nan")), "lag_hi": max(lags, default=float("nan")),
            "tin_fps": tin[0]["fps"] if tin else float("nan"),
            "dunes": [{"elements": r["elements"], "fps": r["fps"], "latency_p95": r["latency_p95"],
                       "display_p50": r["display_p50"]} for r in dunes],
            "frames": FRAMES, "bars": bars, "bars_table": bars_table(bars) if bars else "",
            "met": sum(b["met"] for b in bars), "straddled": sum(b["straddled"] for b in bars),
            "rounds": BAR_ROUNDS, "rows": {case_name(c): r for c, r in rows.items()},
            "costs": costs or {}, "summary": summary, "cpu_ratio": cpu_ratio, "cpu_steps": cpu_steps,
            "latency": latency, "same_cell": same_cell}


if __name__ == "__main__":
    sbrun.main(run)
