#!/usr/bin/python3
"""Figure 7: time of each part (tool, erosion, redundant-vertex detection, vertex removal)
against TIN size N at trace length 0.1 of the diagonal, with the grid at the same number of
cells; log-log fitted exponents in the table."""
import sbrun

PARTS = [("time_s.tool", "tool"), ("time_s.erosion", "erosion"), ("time_s.detect", "detection"),
         ("time_s.remove", "removal")]


def run(ctx):
    import matplotlib.pyplot as plt

    ns = ctx.profile["fig7_n"]
    common = [sbrun.diagonal_path(0.1), "erosion.relax_at_end=false", sbrun.PAPER_RULE]
    jobs = []
    for n in ns:
        jobs.append((sbrun.DIAGONAL_SCENE, "tin", f"fig7/tin-N{n}", common + [f"tin.initial_points={n}"]))
        jobs.append((sbrun.DIAGONAL_SCENE, "grid", f"fig7/grid-N{n}", common + [f"grid.cell_m={sbrun.grid_cell_for(n):.8f}"]))
        jobs.append((sbrun.DIAGONAL_SCENE, "sparse", f"fig7/sparse-N{n}",
                     common + [f"grid.cell_m={sbrun.grid_cell_for(n):.8f}"]))
    s = ctx.run_many("fig7", jobs)
    tin, grid, sparse = s[0::3], s[1::3], s[2::3]

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for key, name in PARTS:
        ax.plot(ns, [r[key] for r in tin], marker="o", label=f"TIN {name}")
    ax.plot(ns, [r["time_s.total"] for r in tin], marker="s", color="k", label="TIN total")
    ax.plot(ns, [r["time_s.total"] for r in grid], marker="^", color="grey", ls="--", label="grid total (same cells)")
    ax.plot(ns, [r["time_s.total"] for r in sparse], marker="v", color="C2", ls=":", label="sparse grid total (same cells)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("model size N (TIN vertices / grid nodes)")
    ax.set_ylabel("time over the whole stroke [s]")
    ax.set_title("Fig. 7: time per part vs model size (trace 0.1 of the diagonal)")
    ax.legend(fontsize=8)
    png = ctx.figure(fig, "fig7_time_vs_size")

    rows = []
    for n, t, g in zip(ns, tin, grid):
        rows.append([n, t["vertices"], t["time_s.tool"], t["time_s.erosion"], t["time_s.detect"], t["time_s.remove"],
                     t["time_s.total"], g["cells"], g["time_s.total"]])
    slopes = {name: sbrun.loglog_slope(ns, [r[key] for r in tin]) for key, name in PARTS}
    slopes["total"] = sbrun.loglog_slope(ns, [r["time_s.total"] for r in tin])
    grid_slope = sbrun.loglog_slope(ns, [r["time_s.total"] for r in grid])
    sparse_slope = sbrun.loglog_slope(ns, [r["time_s.total"] for r in sparse])
    sparse_ratio = sorted(sp["time_s.total"] / max(g["time_s.total"], 1e-30) for sp, g in zip(sparse, grid))
    rows.append(["exponent", "", slopes["tool"], slopes["erosion"], slopes["detection"], slopes["removal"],
                 slopes["total"], "", grid_slope])
    md = ctx.table("fig7_time_vs_size", ["N", "TIN vertices after", "tool s", "erosion s", "detection s",
                                         "removal s", "TIN total s", "grid nodes", "grid total s"], rows)

    last = tin[-1]
    share = {name: last[key] / max(last["time_s.total"], 1e-30) for key, name in PARTS}
    dominant = max(share, key=share.get)
    return {"png": png, "table": md, "n_max": ns[-1], "dominant": dominant, "shares": {k: 100 * v for k, v in share.items()},
            "removal_dominant": dominant == "removal", "slopes": slopes, "grid_slope": grid_slope,
            "sparse_slope": sparse_slope, "sparse_ratio": sparse_ratio[len(sparse_ratio) // 2]}


if __name__ == "__main__":
    sbrun.main(run)
