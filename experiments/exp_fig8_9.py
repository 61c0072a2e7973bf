#!/usr/bin/python3
"""Figures 8 and 9: the time of each part against trace length (0.1 to 1.0 of the diagonal)
at N = 10000 (Fig. 8), and the vertices after the run and the triangles touched by the tool
against trace length (Fig. 9), both back-ends on the same strokes."""
import sbrun
from exp_fig7 import PARTS


def run(ctx):
    import matplotlib.pyplot as plt

    fractions = ctx.profile["trace"]
    n = ctx.profile["fig8_n"]
    jobs = []
    for f in fractions:
        common = [sbrun.diagonal_path(f), "erosion.relax_at_end=false", sbrun.PAPER_RULE]
        jobs.append((sbrun.DIAGONAL_SCENE, "tin", f"fig8/tin-L{f:.2f}", common + [f"tin.initial_points={n}"]))
        jobs.append((sbrun.DIAGONAL_SCENE, "grid", f"fig8/grid-L{f:.2f}", common + [f"grid.cell_m={sbrun.grid_cell_for(n):.8f}"]))
        jobs.append((sbrun.DIAGONAL_SCENE, "sparse", f"fig8/sparse-L{f:.2f}",
                     common + [f"grid.cell_m={sbrun.grid_cell_for(n):.8f}"]))
    s = ctx.run_many("fig8/9", jobs)
    tin, grid, sparse = s[0::3], s[1::3], s[2::3]
    lengths = [sbrun.trace_length(f) for f in fractions]

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for key, name in PARTS:
        ax.plot(lengths, [r[key] for r in tin], marker="o", label=f"TIN {name}")
    ax.plot(lengths, [r["time_s.total"] for r in tin], marker="s", color="k", label="TIN total")
    ax.plot(lengths, [r["time_s.total"] for r in grid], marker="^", color="grey", ls="--", label="grid total")
    ax.plot(lengths, [r["time_s.total"] for r in sparse], marker="v", color="C2", ls=":", label="sparse grid total")
    ax.set_xlabel("trace length [fraction of the diagonal]")
    ax.set_ylabel("time over the whole stroke [s]")
    ax.set_title(f"Fig. 8: time per part vs trace length (N = {n})")
    ax.legend(fontsize=8)
    png8 = ctx.figure(fig, "fig8_time_vs_trace")

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(lengths, [r["vertices"] for r in tin], marker="o", label="TIN vertices after the run")
    ax.plot(lengths, [r["elements_touched"] for r in tin], marker="s", label="triangles touched by the tool")
    ax.plot(lengths, [r["elements_touched"] for r in grid], marker="^", ls="--", label="grid nodes touched by the tool")
    ax.set_xlabel("trace length [fraction of the diagonal]")
    ax.set_ylabel("count")
    ax.set_title(f"Fig. 9: elements vs trace length (N = {n})")
    ax.legend(fontsize=8)
    png9 = ctx.figure(fig, "fig9_elements_vs_trace")

    rows8 = [[f"{L:.3f}", t["stamps"], t["time_s.tool"], t["time_s.erosion"], t["time_s.detect"], t["time_s.remove"],
              t["time_s.total"], g["time_s.total"]] for L, t, g in zip(lengths, tin, grid)]
    sl = {name: sbrun.loglog_slope(lengths, [r[key] for r in tin]) for key, name in PARTS}
    sl_total = sbrun.loglog_slope(lengths, [r["time_s.total"] for r in tin])
    sl_grid = sbrun.loglog_slope(lengths, [r["time_s.total"] for r in grid])
    rows8.append(["exponent", "", sl["tool"], sl["erosion"], sl["detection"], sl["removal"], sl_total, sl_grid])
    md8 = ctx.table("fig8_time_vs_trace", ["trace", "stamps", "tool s", "erosion s", "detection s", "removal s",
                                           "TIN total s", "grid total s"], rows8)
    rows9 = [[f"{L:.3f}", t["vertices"], t["triangles"], t["elements_touched"], g["elements_touched"]]
             for L, t, g in zip(lengths, tin, grid)]
    sl_vert = sbrun.loglog_slope(lengths, [t["vertices"] for t in tin])
    sl_touch = sbrun.loglog_slope(lengths, [t["elements_touched"] for t in tin])
    rows9.append(["exponent", sl_vert, "", sl_touch, sbrun.loglog_slope(lengths, [g["elements_touched"] for g in grid])])
    md9 = ctx.table("fig9_elements_vs_trace", ["trace", "TIN vertices", "TIN triangles", "TIN triangles touched",
                                               "grid nodes touched"], rows9)

    sl_sparse = sbrun.loglog_slope(lengths, [r["time_s.total"] for r in sparse])
    return {"png8": png8, "png9": png9, "table8": md8, "table9": md9, "slopes": sl, "total_slope": sl_total,
            "grid_slope": sl_grid, "sparse_slope": sl_sparse, "touched_slope": sl_touch, "vertex_slope": sl_vert,
            "n": n}


if __name__ == "__main__":
    sbrun.main(run)
