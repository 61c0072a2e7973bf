#!/usr/bin/python3
"""Memory: model bytes against resolution for the three back-ends, and at equal accuracy -- the
grid resolution whose height error against a fine reference matches the TIN's. The sparse grid
holds the dense grid's heights (bit for bit), so its error is the grid's at the same cell size."""
import math

import sbrun


def final_raster(ctx, name):
    with sbrun.read_h5(ctx.runs / f"{name}.h5") as f:
        return f["/final/raster"][()]


def rmse(a, b):
    import numpy as np
    return float(np.sqrt(np.mean((a - b) ** 2)))


def run(ctx):
    import matplotlib.pyplot as plt

    cells = ctx.profile["memory_cells"]
    stroke = [sbrun.diagonal_path(0.1)]
    jobs = [(sbrun.DIAGONAL_SCENE, "grid", f"memory/grid-ref-{ctx.profile['reference_cell']}",
             stroke + [f"grid.cell_m={ctx.profile['reference_cell']}"])]
    jobs += [(sbrun.DIAGONAL_SCENE, "grid", f"memory/grid-{c}", stroke + [f"grid.cell_m={c}"]) for c in cells]
    tin_variants = [("TIN (4 corners + tool)", []), ("TIN, contour subdivided 2.5 mm", ["tin.contour_subdivision_m=0.0025"]),
                    # The TIN stamps the corners its mesh resolves (one per tin.refine_m of perimeter):
                    # a 64-gon needs a refinement of 2 pi r / 64.
                    ("TIN, 64-gon tool, refined to resolve it", ["tool.sides=64", "tin.refine_m=0.001944"])]
    jobs += [(sbrun.DIAGONAL_SCENE, "tin", f"memory/tin-{i}", stroke + o) for i, (_, o) in enumerate(tin_variants)]
    jobs += [(sbrun.DIAGONAL_SCENE, "sparse", f"memory/sparse-{c}", stroke + [f"grid.cell_m={c}"]) for c in cells]
    s = ctx.run_many("memory", jobs)
    sparse = s[len(s) - len(cells):]
    s = s[:len(s) - len(cells)]
    ref_name = jobs[0][2]
    ref = final_raster(ctx, ref_name)
    grid = s[1:1 + len(cells)]
    tins = s[1 + len(cells):]
    grid_err = [rmse(final_raster(ctx, j[2]), ref) for j in jobs[1:1 + len(cells)]]
    tin_err = [rmse(final_raster(ctx, j[2]), ref) for j in jobs[1 + len(cells):1 + len(cells) + len(tin_variants)]]

    # The grid bytes at the TIN's error, interpolated log-log between neighbouring resolutions.
    def grid_bytes_at(err):
        pts = sorted(zip(grid_err, [g["memory_bytes"] for g in grid]))
        for (e0, b0), (e1, b1) in zip(pts, pts[1:]):
            if e0 <= err <= e1 and e0 > 0:
                t = (math.log(err) - math.log(e0)) / (math.log(e1) - math.log(e0)) if e1 > e0 else 0
                return math.exp(math.log(b0) + t * (math.log(b1) - math.log(b0)))
        return float("nan")

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    a1.plot([g["cells"] for g in grid], [g["memory_bytes"] for g in grid], marker="^", label="grid")
    a1.plot([g["cells"] for g in sparse], [g["memory_bytes"] for g in sparse], marker="v", label="sparse grid (OpenVDB)")
    for (label, _), t in zip(tin_variants, tins):
        a1.plot([t["vertices"]], [t["memory_bytes"]], marker="o", ls="", label=label)
    a1.set_xscale("log")
    a1.set_yscale("log")
    a1.set_xlabel("elements (grid nodes / TIN vertices)")
    a1.set_ylabel("model bytes")
    a1.set_title("memory against resolution")
    a1.legend(fontsize=8)
    a2.plot([g["memory_bytes"] for g in grid], grid_err, marker="^", label="grid (cell sizes)")
    a2.plot([g["memory_bytes"] for g in sparse], grid_err, marker="v", label="sparse grid (same heights)")
    for c, g, e in zip(cells, grid, grid_err):
        a2.annotate(f"{c * 1000:g} mm", (g["memory_bytes"], e), fontsize=7)
    for (label, _), t, e in zip(tin_variants, tins, tin_err):
        a2.plot([t["memory_bytes"]], [e], marker="o", ls="", label=label)
    a2.set_xscale("log")
    a2.set_yscale("log")
    a2.set_xlabel("model bytes")
    a2.set_ylabel("height RMSE vs fine grid [m]")
    a2.set_title(f"accuracy against memory (reference: {ctx.profile['reference_cell'] * 1000:g} mm grid)")
    a2.legend(fontsize=8)
    png = ctx.figure(fig, "memory")

    rows = [[f"grid {c * 1000:g} mm", g["cells"], g["memory_bytes"], e] for c, g, e in zip(cells, grid, grid_err)]
    rows += [[label, t["vertices"], t["memory_bytes"], e] for (label, _), t, e in zip(tin_variants, tins, tin_err)]
    rows += [[f"sparse grid {c * 1000:g} mm", g["cells"], g["memory_bytes"], e] for c, g, e in zip(cells, sparse, grid_err)]
    md = ctx.table("memory", ["model", "elements", "bytes", "RMSE vs reference [m]"], rows)
    t0, e0 = tins[0], tin_err[0]
    gb = grid_bytes_at(e0)
    # The claim is judged at equal accuracy; without an equal-accuracy grid, against the finest grid.
    smaller = gb > t0["memory_bytes"] if not math.isnan(gb) else t0["memory_bytes"] < grid[-1]["memory_bytes"]
    tin_per_vertex = t0["memory_bytes"] / t0["vertices"]
    grid_per_node = grid[-1]["memory_bytes"] / grid[-1]["cells"]
    sp, g = sparse[-1]["memory_bytes"], grid[-1]["memory_bytes"]
    at_equal = "" if math.isnan(gb) else f"{gb / 1e3:.0f} kB"
    return {"png": png, "table": md, "tin_error": e0, "grid_error_min": min(grid_err), "grid_error_max": max(grid_err),
            "grid_kb_at_equal": gb / 1e3, "tin_kb": t0["memory_bytes"] / 1e3, "tin_vertices": t0["vertices"],
            "smaller": smaller, "finest_mm": cells[-1] * 1000, "finest_nodes": grid[-1]["cells"], "finest_kb": g / 1e3,
            "tin_per_vertex": tin_per_vertex, "grid_per_node": grid_per_node,
            "sparse_kb": sp / 1e3, "sparse_vs_grid": sp / g, "sparse_vs_tin": sp / t0["memory_bytes"],
            "summary": {"tin": {"memory at equal accuracy": f"{t0['memory_bytes'] / 1e3:.0f} kB"},
                        "grid": {"memory at equal accuracy": at_equal or "no grid of the TIN's error"},
                        "sparse": {"memory at equal accuracy": f"{sp / g:.2f}x the grid's bytes"}}}


if __name__ == "__main__":
    sbrun.main(run)
