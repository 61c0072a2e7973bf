#!/usr/bin/python3
"""Figures 5 and 6: the TIN (shaded and wireframe) and the grid after the same stroke, side
by side, with a map of where their heights differ."""
import json
import shutil

import sbrun


def run(ctx):
    out = ctx.runs / "fig5_6"
    what = ["compare", sbrun.DIAGONAL_SCENE, "--backends", "tin,grid", "--set", sbrun.PAPER_RULE]
    if not ctx.is_current(out, what):  # made by another binary, or never: make it again
        shutil.rmtree(out, ignore_errors=True)
        ctx.sandbench_cmd(*what, "--out", out)
        ctx.mark_current(out, what)
    tin_run = out / "flat_stroke-tin.h5"
    grid_run = out / "flat_stroke-grid.h5"
    pictures = {
        "fig5_tin_shaded.png": [tin_run, "--view", "oblique"],
        "fig5_tin_wireframe.png": [tin_run, "--view", "top", "--wireframe"],
        "fig6_grid_shaded.png": [grid_run, "--view", "oblique"],
        "fig6_grid_wireframe.png": [grid_run, "--view", "top", "--wireframe"],
    }
    for name, args in pictures.items():
        ctx.sandbench_cmd("render", args[0], "-o", ctx.results / name, *args[1:])
    shutil.copyfile(out / "side_by_side.png", ctx.results / "fig5_6_side_by_side.png")
    shutil.copyfile(out / "difference.png", ctx.results / "fig5_6_difference.png")
    report = json.loads((out / "summary.json").read_text())
    tin, grid = report["runs"]
    diff = report["differences"][0]
    return {"tin_vertices": tin["vertices"], "tin_triangles": tin["triangles"], "tin_kb": tin["memory_bytes"] / 1e3,
            "grid_nodes": grid["cells"], "grid_kb": grid["memory_bytes"] / 1e3, "rmse_mm": diff["rmse_m"] * 1000,
            "max_mm": diff["max_abs_m"] * 1000}


if __name__ == "__main__":
    sbrun.main(run)
