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

    def verdict(value, target, tol):
        return "reproduced" if abs(value - target) <= tol else "not reproduced"

    return f"""## Figure 8: time of each part against trace length

![fig8]({png8})

{md8}
- *Paper: erosion grows as O(n) in trace length.* Ours: {verdict(sl['erosion'], 1.0, 0.25)} (exponent
  {sl['erosion']:.2f}).
- *Paper: vertex removal grows faster than linearly in trace length.* Ours: exponent {sl['removal']:.2f} for
  removal ({'reproduced' if sl['removal'] > 1.15 else 'not reproduced: linear, since each stamp removes a bounded number of vertices near the tool'}),
  {sl_total:.2f} for the TIN's total, {sl_grid:.2f} for the grid's,
  {sbrun.loglog_slope(lengths, [r["time_s.total"] for r in sparse]):.2f} for the sparse grid's.

## Figure 9: elements against trace length

![fig9]({png9})

{md9}
- *Paper: the number of vertices after the run and of triangles touched by the tool are nearly linear in the
  trace length.* Ours: triangles touched {verdict(sl_touch, 1.0, 0.2)} (exponent {sl_touch:.2f}); vertices after
  the run grow with exponent {sl_vert:.2f} on top of the {n} initial vertices (the stroke adds a band of
  vertices proportional to its length, a small part of the total).
"""


if __name__ == "__main__":
    sbrun.main(run)
