#!/usr/bin/python3
"""Volume drift over a long stroke, per phase (tool, erosion, simplification), both back-ends."""
import sbrun

# The TIN twice, both explicit: without the volume correction (the paper's method) and with it
# (tin.conserve_volume, this project's default): the paper does not correct volume.
VARIANTS = [("tin, no correction", "tin", ["tin.conserve_volume=false"]),
            ("tin, conserve_volume (default)", "tin", ["tin.conserve_volume=true"]),
            ("grid double", "grid", []), ("grid float", "grid", ["grid.storage=float"]),
            ("sparse double", "sparse", [])]


def run(ctx):
    import matplotlib.pyplot as plt
    import numpy as np

    stroke = [sbrun.diagonal_path(1.0), f"stroke.repeat={ctx.profile['drift_repeat']}"]
    jobs = [(sbrun.DIAGONAL_SCENE, b, f"drift/{label.split(' (')[0].replace(' ', '_').replace(',', '')}", stroke + o)
            for label, b, o in VARIANTS]
    s = ctx.run_many("drift", jobs)

    fig, axes = plt.subplots(1, len(VARIANTS), figsize=(4 * len(VARIANTS), 3.6), sharey=False)
    rows = []
    for ax, (label, _, _), job, summary in zip(axes, VARIANTS, jobs, s):
        with sbrun.read_h5(ctx.runs / f"{job[2]}.h5") as f:
            steps = {k: f["steps"][k][()] for k in f["steps"]}
        v0 = summary["volume_initial"]
        x = np.arange(len(steps["stamp"]))
        for phase in ("tool", "erosion", "simplify"):
            ax.plot(x, np.cumsum(steps[f"volume_delta_{phase}"]) / v0, label=phase)
        ax.plot(x, (steps["volume_m3"] - v0 - np.cumsum(steps["volume_added"])) / v0, color="k", lw=1, label="total")
        ax.set_title(label, fontsize=9)
        ax.set_xlabel("step")
        ax.ticklabel_format(axis="y", style="sci", scilimits=(0, 0))
        rows.append([label, summary["stamps"], summary["volume_delta_tool"] / v0, summary["volume_delta_erosion"] / v0,
                     summary["volume_delta_simplify"] / v0, summary["volume_drift_rel"], summary["time_s.total"]])
    axes[0].set_ylabel("cumulative volume change / initial volume")
    axes[0].legend(fontsize=8)
    png = ctx.figure(fig, "drift")
    md = ctx.table("drift", ["model", "stamps", "tool (rel)", "erosion (rel)", "simplify (rel)", "total drift (rel)",
                             "time s"], rows)
    tin, tin_c, gd, gf, sd = s
    phases = {p: abs(tin[f"volume_delta_{p}"]) for p in ("tool", "erosion", "simplify")}
    worst = max(phases, key=phases.get)
    return {"png": png, "table": md, "grid_double": gd["volume_drift_rel"], "grid_float": gf["volume_drift_rel"],
            "sparse": sd["volume_drift_rel"], "tin": tin["volume_drift_rel"], "tin_corrected": tin_c["volume_drift_rel"],
            "worst_phase": worst, "worst_share": 100 * phases[worst] / max(sum(phases.values()), 1e-300),
            "correction_cost": tin_c["time_s.total"] / max(tin["time_s.total"], 1e-30)}


if __name__ == "__main__":
    sbrun.main(run)
