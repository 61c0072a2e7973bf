#!/usr/bin/python3
"""alpha_flat: vertex count and height error against the simplification threshold (the
trade-off of the paper's Section 5), on the dunes scene with its curved stroke; the paper's
step 3 alone (tin.coarsen = false)."""
import sbrun

SCENE = sbrun.SCENES / "dunes.toml"


def run(ctx):
    import matplotlib.pyplot as plt
    import numpy as np

    alphas = ctx.profile["alpha"]
    if 0.0 not in alphas:
        alphas = [0.0] + list(alphas)
    jobs = [(SCENE, "tin", f"alpha_flat/tin-a{a:g}", [f"tin.alpha_flat_deg={a}", "tin.coarsen=false", sbrun.PAPER_RULE]) for a in alphas]
    s = ctx.run_many("alpha_flat", jobs)
    rasters = []
    for j in jobs:
        with sbrun.read_h5(ctx.runs / f"{j[2]}.h5") as f:
            rasters.append(f["/final/raster"][()])
    ref = rasters[alphas.index(0.0)]
    err = [float(np.sqrt(np.mean((r - ref) ** 2))) for r in rasters]
    maxerr = [float(np.max(np.abs(r - ref))) for r in rasters]

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    xs = [max(a, 0.01) for a in alphas]
    ax.plot(xs, [r["vertices"] for r in s], marker="o", color="C0", label="vertices after the run")
    ax.set_xscale("log")
    ax.set_xlabel("alpha_flat [degrees] (0 plotted at 0.01)")
    ax.set_ylabel("vertices", color="C0")
    ax2 = ax.twinx()
    ax2.plot(xs, [max(e, 1e-9) for e in err], marker="s", color="C3", label="RMSE vs alpha_flat = 0")
    ax2.set_yscale("log")
    ax2.set_ylabel("height RMSE vs no simplification [m]", color="C3")
    ax.set_title("alpha_flat: model size against lost detail (dunes)")
    png = ctx.figure(fig, "alpha_flat")
    rows = [[a, r["vertices"], r["triangles"], e, m, r["time_s.total"]] for a, r, e, m in zip(alphas, s, err, maxerr)]
    md = ctx.table("alpha_flat", ["alpha_flat deg", "vertices", "triangles", "RMSE m", "max error m", "time s"], rows)
    i04 = alphas.index(0.4) if 0.4 in alphas else len(alphas) // 2
    fewer = s[-1]["vertices"] < 0.95 * s[0]["vertices"]
    return {"png": png, "table": md, "vertices_none": s[0]["vertices"], "vertices_mid": s[i04]["vertices"],
            "alpha_mid": alphas[i04], "err_mid": err[i04], "vertices_max": s[-1]["vertices"], "alpha_max": alphas[-1],
            "err_max": err[-1], "tradeoff": fewer and err[-1] > err[0]}


if __name__ == "__main__":
    sbrun.main(run)
