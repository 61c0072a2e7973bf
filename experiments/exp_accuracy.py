#!/usr/bin/python3
"""Accuracy against time: pile, crater and trench on both back-ends over resolution sweeps
(grid cell size with 4 and 8 neighbours; TIN tool polygon sides, contour subdivision, erosion
refinement and curvature refinement), each with both erosion rules (`edge`, the paper's;
`gradient`), time per step against error on one set of axes, Pareto fronts marked. The trench is dug at several
azimuths and scored by its worst one, so no stencil is judged on its best direction only."""
import math

import sbrun
from exp_orientation import turned

CASES = {
    # reference scene, error metric, how to read it
    "pile": ("pile.toml", "reference.rmse_m", "height RMSE vs cone [m]"),
    "crater": ("crater.toml", "reference.rmse_m", "height RMSE vs crater [m]"),
    "trench": ("trench_azimuth.toml", "trench.wall_worst_error_deg",
               "worst |wall section - critical| over azimuths [deg]"),
}
# The tool radius of crater.toml (its TIN sweep is over polygon sides).
TOOL_RADIUS_M = {"crater": 0.02}
# The crater has no erosion (one bare stamp): it runs once, with the edge rule named explicitly.
RULES = {"pile": ["edge", "gradient"], "crater": ["edge"], "trench": ["edge", "gradient"]}
# Trench azimuths per profile: along x, between the 8-neighbour stencil's directions, diagonal
# (the full profile too: its TIN trench with 1 mm refinement takes minutes per azimuth and rule;
# exp_orientation.py sweeps the azimuths at the scenes' resolution).
AZIMUTHS = {"tiny": [22.5], "paper": [0, 22.5, 45], "full": [0, 22.5, 45]}
# Measured on a loaded 2-core machine with 2 workers: paper 125 runs, 126 CPU-s, 4 min wall; a
# third of it the TIN trench with 2 mm refinement (6 runs of 6 to 18 CPU-s).
COST = {"tiny": "a few CPU-seconds", "paper": "about 2 CPU-minutes", "full": "over 20 CPU-minutes"}


def sweeps(profile_name, case):
    """(label, backend, overrides) of every model in the sweep of one case. A pour tool has no
    polygon, so the pile's TIN sweep is over erosion refinement; the crater has no erosion."""
    cells = {"tiny": [0.004, 0.002], "paper": [0.004, 0.002, 0.001], "full": [0.004, 0.002, 0.001, 0.0005]}[profile_name]
    grid = [(f"grid {c * 1000:g} mm {n}-nb", "grid", [f"grid.cell_m={c}", f"grid.neighbours={n}"])
            for c in cells for n in (4, 8)]
    # The sparse grid has the dense grid's heights; its points show the price of its storage.
    grid += [(f"sparse {c * 1000:g} mm 8-nb", "sparse", [f"grid.cell_m={c}", "grid.neighbours=8"]) for c in cells]
    sides = {"tiny": [16, 32], "paper": [16, 32, 64], "full": [16, 32, 64, 128]}[profile_name]
    # A 1 mm refinement makes the TIN trench take minutes; it is in the full profile only.
    refine = {"tiny": [0.0], "paper": [0.0, 0.004, 0.002], "full": [0.0, 0.004, 0.002, 0.001]}[profile_name]
    tin = []
    if case == "crater":
        # The TIN stamps a convex tool with as many corners as its mesh resolves (about one per
        # tin.refine_m of perimeter, README `tool.sides`): each polygon comes with the refinement
        # that resolves it, so the sweep is over resolution, not over corners the TIN would drop.
        # (The trench's TIN sweep is over refinement alone, which sets its corners the same way.)
        perimeter = 2 * math.pi * TOOL_RADIUS_M[case]
        tin += [(f"tin {s}-gon", "tin", [f"tool.sides={s}", f"tin.refine_m={0.99 * perimeter / s:.6f}"]) for s in sides]
        tin += [(f"tin {sides[-1]}-gon subdiv 2 mm", "tin", [f"tool.sides={sides[-1]}",
                 f"tin.refine_m={0.99 * perimeter / sides[-1]:.6f}", "tin.contour_subdivision_m=0.002"])]
    if case != "crater":
        # pile.toml refines by curvature at rest (its [tin] section): on the pile every row sets
        # its refinement itself, so that it is what its label says.
        plain = [sbrun.NO_CURVATURE] if case == "pile" else []
        always = ["tin.curvature_when=always"] if case == "pile" else []
        tin += [(f"tin refine {r * 1000:g} mm" if r > 0 else "tin refine default", "tin", [f"tin.refine_m={r}"] + plain)
                for r in refine]
        # Refinement where facet gradients jump (the apex, the toe, a trench's edges), at the
        # default edge length elsewhere: the TIN's own way to spend vertices on accuracy.
        if profile_name != "tiny":
            tin += [("tin curved 0.2 mm", "tin", ["tin.curvature_tolerance_m=0.0002"] + always)]
            if case == "pile":
                tin += [("tin curved 0.5 mm at rest (pile.toml)", "tin", [])]
            # The same refinement only while the sand settles: the strokes' steps cost what
            # the default TIN's do, and the surface at rest gets the creases refined.
            tin += [("tin curved 0.2 mm at rest", "tin",
                     ["tin.curvature_tolerance_m=0.0002", "tin.curvature_when=settling"])]
    return grid + tin


def pareto(points):
    """Indices of the points not dominated in (time, error), sorted by time."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    front, best = [], float("inf")
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def models(profile_name):
    """(case, label, backend, rule, [(azimuth, overrides)]) of every model: a model is one point
    of the chart, the trench's over several azimuths."""
    out = []
    for case in CASES:
        azimuths = AZIMUTHS[profile_name] if case == "trench" else [None]
        for label, backend, overrides in sweeps(profile_name, case):
            for rule in RULES[case]:
                runs = [(az, overrides + ([] if az is None else turned(case, az)) + [f"erosion.rule={rule}"])
                        for az in azimuths]
                out.append((case, label, backend, rule, runs))
    return out


def run_name(case, label, rule, az):
    safe = label.replace(" ", "_").replace("-", "")
    return f"accuracy/{case}-{safe}-{rule}" + ("" if az is None else f"-{az:g}")


def error_of(case, runs):
    """The model's error: the trench's worst section over its azimuths, else the RMSE."""
    if case == "trench":
        return max(r["trench.wall_worst_error_deg"] for r in runs)
    return runs[0][CASES[case][1]]


def median(values):
    v = sorted(values)
    return v[len(v) // 2] if len(v) % 2 else 0.5 * (v[len(v) // 2 - 1] + v[len(v) // 2])


_announced = set()


def run(ctx):
    import matplotlib.pyplot as plt

    index = models(ctx.profile_name)
    if ctx.profile_name not in _announced:  # the driver calls run() once per round
        _announced.add(ctx.profile_name)
        n = sum(len(runs) for *_, runs in index)
        sbrun.progress(f"  accuracy: {n} runs in the {ctx.profile_name} profile ({COST[ctx.profile_name]})")
    jobs = [(sbrun.SCENES / CASES[case][0], backend, run_name(case, label, rule, az), o)
            for case, label, backend, rule, runs in index for az, o in runs]
    flat = iter(ctx.run_many("accuracy", jobs))
    s = [[next(flat) for _ in runs] for *_, runs in index]  # the summaries of each model's runs

    fig, axes = plt.subplots(1, len(CASES), figsize=(5.2 * len(CASES), 4.4))
    for ax, case in zip(axes, CASES):
        for backend, marker, colour in (("grid", "^", "C0"), ("sparse", "v", "C2"), ("tin", "o", "C3")):
            for rule in RULES[case]:
                pts = [(median(r["step_ms.p50"] for r in rs), max(error_of(case, rs), 1e-9), lab)
                       for (c, lab, b, ru, _), rs in zip(index, s) if c == case and b == backend and ru == rule]
                hollow = rule == "edge" and len(RULES[case]) > 1
                ax.scatter([p[0] for p in pts], [p[1] for p in pts], marker=marker, alpha=0.7,
                           facecolors="none" if hollow else colour, edgecolors=colour,
                           label=f"{backend} {rule}" if len(RULES[case]) > 1 else backend)
                for p in pts:
                    ax.annotate(p[2].replace(backend + " ", ""), (p[0], p[1]), fontsize=6, alpha=0.8)
                front = [pts[i] for i in pareto([(p[0], p[1]) for p in pts])]
                first = (backend, rule) == ("grid", RULES[case][-1])
                ax.step([p[0] for p in front], [p[1] for p in front], where="post", color=colour, lw=1.2,
                        ls="--" if hollow else "-", label="Pareto fronts" if first else None)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("time per step, median [ms]")
        ax.set_ylabel(CASES[case][2])
        ax.set_title(case + (" (hollow, dashed: edge rule; filled: gradient)" if len(RULES[case]) > 1 else ""),
                     fontsize=9)
        ax.legend(fontsize=6)
    png = ctx.figure(fig, "accuracy_speed")
    rows = []
    for (case, label, backend, rule, _), rs in zip(index, s):
        angle = max(r.get("pile.flank_angle_deg", r.get("trench.wall_angle_deg", float("-inf"))) for r in rs)
        rows.append([case, label, rule, len(rs), median(r["step_ms.p50"] for r in rs), error_of(case, rs),
                     rs[0].get("reference.max_error_m", ""), "" if angle == float("-inf") else angle,
                     rs[0].get("pile.roundness", ""), max((r["volume_drift_rel"] for r in rs), key=abs),
                     max(r["max_slope_excess_deg"] for r in rs), max(r["memory_bytes"] for r in rs),
                     # (the crater is one stamp without erosion: nothing to settle)
                     "no erosion" if case == "crater" else f"{sum(bool(r['settled']) for r in rs)}/{len(rs)}"])
    md = ctx.table("accuracy", ["case", "model", "rule", "azimuths", "step ms p50", "error", "max error m",
                                "angle deg", "roundness", "drift rel", "slope excess deg", "bytes", "runs settled"],
                   rows)

    def pick(case, rule, pred):
        return [(rs, lab) for (c, lab, b, ru, _), rs in zip(index, s) if c == case and ru == rule and pred(lab, b)]

    def best_flank(rule, backend):
        vals = [(rs[0]["pile.flank_angle_deg"], lab) for rs, lab in pick("pile", rule, lambda lab, b: b == backend)]
        return min(vals, key=lambda v: abs(v[0] - 30.0)) if vals else (float("nan"), "")

    def roundness(rule, pred):
        vals = [rs[0]["pile.roundness"] for rs, _ in pick("pile", rule, pred)]
        return (f"{min(vals):.3f}..{max(vals):.3f}" if vals else "n/a")

    def trench_best(rule, backend):
        vals = [(error_of("trench", rs), lab) for rs, lab in pick("trench", rule, lambda lab, b: b == backend)]
        return min(vals) if vals else (float("nan"), "")

    rules = []
    for rule in RULES["pile"]:
        pg, pt = best_flank(rule, "grid"), best_flank(rule, "tin")
        tg, tt = trench_best(rule, "grid"), trench_best(rule, "tin")
        rules.append({"rule": rule, "grid_flank": pg[0], "grid_flank_model": pg[1], "tin_flank": pt[0],
                      "tin_flank_model": pt[1], "round_4nb": roundness(rule, lambda lab, b: "4-nb" in lab),
                      "round_8nb": roundness(rule, lambda lab, b: "8-nb" in lab),
                      "round_tin": roundness(rule, lambda lab, b: b == "tin"), "trench_grid": tg[0],
                      "trench_grid_model": tg[1], "trench_tin": tt[0], "trench_tin_model": tt[1]})
    return {"png": png, "table": md, "rules": rules, "azimuths": AZIMUTHS[ctx.profile_name]}


if __name__ == "__main__":
    sbrun.main(run)
