#!/usr/bin/python3
"""Settling against resolution: the paper's stroke (flat_stroke.toml) on grids of ever smaller
cells, stroke and settling timed apart, with the work (erosion updates) that settling took.
A relaxation that moves a fixed fraction of the excess per visit is diffusion-like: the passes
to settle grow as (L / h)^2 while the active region grows as n, so the time can grow as n^2;
this table says how the grids scale here, for both erosion rules."""
import sbrun

# (label, backend, overrides): the default rule on both grids, and the paper's rule on the dense one;
# the dense grid also on two threads (its large dense passes run two bands of rows at once: the
# same heights and work, other times).
VARIANTS = [("grid", "grid", []), ("grid (edge rule)", "grid", [sbrun.PAPER_RULE]), ("sparse", "sparse", []),
            ("grid, 2 threads", "grid", ["grid.threads=2"])]
TARGET_S, TARGET_EXPONENT = 3.0, 1.2  # at 5.1 M nodes; over 0.32 M..5.1 M nodes


def run(ctx):
    import matplotlib.pyplot as plt

    cells = ctx.profile["settle_cells"]
    scene = sbrun.SCENES / "flat_stroke.toml"
    jobs = [(scene, backend, f"settling/{label.replace(' ', '_').replace('(', '').replace(')', '')}-c{c}",
             extra + [f"grid.cell_m={c}"]) for label, backend, extra in VARIANTS for c in cells]
    s = ctx.run_many("settling", jobs)
    by_variant = {label: s[i * len(cells):(i + 1) * len(cells)] for i, (label, _, _) in enumerate(VARIANTS)}

    rows, fits = [], {}
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for (label, _, _), marker in zip(VARIANTS, "os^D"):
        runs = by_variant[label]
        nodes = [r["cells"] for r in runs]
        total = [r["time_s.total"] + r["time_s.relax"] for r in runs]
        for r, t in zip(runs, total):
            rows.append([label, r["cells"], r["time_s.total"], r["time_s.relax"], t, r["erosion_updates"],
                         r["relax_updates"], r["relax_steps"], "yes" if r["settled"] else "no", r["max_slope_excess_deg"],
                         r["volume_drift_rel"]])
        # From 0.32 M nodes up (smaller grids settle in milliseconds: noise), unless the profile
        # has fewer than two such sizes.
        every = [(n, t, r["relax_updates"]) for n, t, r in zip(nodes, total, runs)]
        big = [b for b in every if b[0] >= 3e5]
        big = big if len(big) >= 2 else every
        fits[label] = (sbrun.loglog_slope([b[0] for b in big], [b[1] for b in big]),
                       sbrun.loglog_slope([b[0] for b in big], [b[2] for b in big]))
        rows.append([label, f"exponent ({big[0][0]}..{big[-1][0]} nodes)", "", "", fits[label][0], "", fits[label][1], "", "",
                     "", ""])
        ax.plot(nodes, total, marker=marker, label=label)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("grid nodes")
    ax.set_ylabel("stroke + settling [s]")
    ax.set_title("Settling against resolution (flat_stroke, 21 stamps)")
    ax.legend(fontsize=8)
    png = ctx.figure(fig, "settling")
    md = ctx.table("settling", ["variant", "nodes", "stroke s", "settling s", "stroke + settling s",
                                "stroke updates", "settling updates", "settling calls", "settled", "slope excess deg", "drift (rel)"],
                   rows)

    grid = by_variant["grid"]
    largest = grid[-1]
    largest_s = largest["time_s.total"] + largest["time_s.relax"]
    exponent = fits["grid"][0]
    two = by_variant["grid, 2 threads"][-1]
    two_s = two["time_s.total"] + two["time_s.relax"]
    meets = largest["cells"] >= 5e6 and largest_s <= TARGET_S and exponent <= TARGET_EXPONENT
    return {"png": png, "table": md, "cell_first_mm": cells[0] * 1000, "cell_last_mm": cells[-1] * 1000,
            "largest_s": largest_s, "largest_mnodes": largest["cells"] / 1e6, "exponent": exponent,
            "update_exponent": fits["grid"][1], "target_s": TARGET_S, "target_exponent": TARGET_EXPONENT,
            "target": "met" if meets else "not met" if largest["cells"] >= 5e6 else "not measured at 5.1 M nodes",
            "edge_exponent": fits["grid (edge rule)"][0], "sparse_exponent": fits["sparse"][0], "two_s": two_s,
            "two_mnodes": two["cells"] / 1e6, "same_updates": two["relax_updates"] == largest["relax_updates"],
            "summary": {"grid": {"settling time": f"{largest_s:.2f} s at {largest['cells'] / 1e6:.1f} M nodes "
                                                  f"(exponent {exponent:.2f})"}}}


if __name__ == "__main__":
    sbrun.main(run)
