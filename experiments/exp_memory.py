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
    if math.isnan(gb):
        equal = (f"the TIN's error ({e0:.2e} m) lies outside the grid sweep's range "
                 f"({min(grid_err):.2e}..{max(grid_err):.2e} m), so no equal-accuracy grid is interpolated")
    else:
        equal = (f"at the TIN's error ({e0:.2e} m) a grid needs about {gb / 1e3:.0f} kB against the TIN's "
                 f"{t0['memory_bytes'] / 1e3:.0f} kB ({gb / t0['memory_bytes']:.1f}x)")
    # The claim is judged at equal accuracy; without an equal-accuracy grid, against the finest grid.
    smaller = gb > t0["memory_bytes"] if not math.isnan(gb) else t0["memory_bytes"] < grid[-1]["memory_bytes"]
    return f"""## Memory against resolution and at equal accuracy

![memory]({png})

{md}
- *Paper: a TIN needs significantly less memory than a grid.* Ours: {'reproduced' if smaller else 'not reproduced at equal accuracy'}
  for a flat scene: the TIN holds {t0['vertices']} vertices ({t0['memory_bytes'] / 1e3:.0f} kB) after the stroke,
  the {cells[-1] * 1000:g} mm grid {grid[-1]['cells']} nodes ({grid[-1]['memory_bytes'] / 1e3:.0f} kB); {equal}.
  A TIN vertex costs about 170 bytes against a grid node's 10, so the TIN wins only where it needs at least
  17 times fewer elements than a grid of the same accuracy: on large flat areas, not around a single stroke.
- The sparse grid stores only the 8 x 8 node blocks the stroke disturbed: at {cells[-1] * 1000:g} mm it holds
  {sparse[-1]['memory_bytes'] / 1e3:.0f} kB ({sparse[-1]['memory_bytes'] / grid[-1]['memory_bytes']:.2f}x the dense grid,
  {sparse[-1]['memory_bytes'] / t0['memory_bytes']:.2f}x the TIN) with the dense grid's accuracy; its bytes
  follow the disturbed area, not the domain.
"""


if __name__ == "__main__":
    sbrun.main(run)
