#!/usr/bin/python3
"""The poured pile at several pour points. pile.toml pours at the domain's centre, which is a node of
its 2.5 mm grid and a point of the TIN's first diagonal: special points for both. How close a model
comes to the analytic cone depends on where the pour lands relative to its elements, so a single point
says little: this table pours the same sand at the scene's point and at seven others within two grid
cells of it (a Halton sequence), with each back-end's defaults, and compares the distributions."""
import statistics

import sbrun

CENTRE = (0.15, 0.15)
REACH = 0.005  # two grid cells either way


def halton(i, base):
    f, r = 1.0, 0.0
    while i > 0:
        f /= base
        r += f * (i % base)
        i //= base
    return r


def positions(count):
    """The scene's pour point, then count - 1 Halton points in the square of half-side REACH around it."""
    out = [CENTRE]
    for i in range(1, count):
        out.append((round(CENTRE[0] + REACH * (2 * halton(i, 2) - 1), 5),
                    round(CENTRE[1] + REACH * (2 * halton(i, 3) - 1), 5)))
    return out


COUNT = {"tiny": 3, "paper": 8, "full": 16}
# (label, backend, overrides): each back-end as the scene asks, and the TIN without the scene's
# curvature refinement at rest (its [tin] section) for what that refinement buys.
MODELS = [("grid", "grid", []), ("tin", "tin", []), ("tin plain", "tin", [sbrun.NO_CURVATURE])]


def run(ctx):
    points = positions(COUNT[ctx.profile_name])
    jobs = [(sbrun.SCENES / "pile.toml", backend, f"pile_positions/{sbrun.slug(label)}-{k}",
             [f"stroke.path_m=[[{x}, {y}]]"] + overrides)
            for k, (x, y) in enumerate(points) for label, backend, overrides in MODELS]
    s = ctx.run_many("pile_positions", jobs)
    rows, rmse = [], {label: [] for label, _, _ in MODELS}
    for k, (x, y) in enumerate(points):
        runs = s[len(MODELS) * k:len(MODELS) * (k + 1)]
        for (label, _, _), r in zip(MODELS, runs):
            rmse[label].append(r["reference.rmse_m"] * 1e6)
        grid, tin, plain = runs
        rows.append([f"({x:.4f}, {y:.4f})" + (" (the scene's)" if k == 0 else ""), grid["reference.rmse_m"] * 1e6,
                     grid["pile.flank_angle_deg"], grid["pile.roundness"], tin["reference.rmse_m"] * 1e6,
                     tin["pile.flank_angle_deg"], tin["pile.roundness"], tin["reference.rmse_m"] / grid["reference.rmse_m"],
                     plain["reference.rmse_m"] * 1e6, plain["reference.rmse_m"] / grid["reference.rmse_m"]])
    md = ctx.table("pile_positions", ["pour point (m)", "grid RMSE um", "grid flank deg", "grid roundness", "tin RMSE um",
                                      "tin flank deg", "tin roundness", "RMSE tin / grid",
                                      "tin without refinement at rest RMSE um", "its RMSE / grid's"], rows)
    g, t, p = rmse["grid"], rmse["tin"], rmse["tin plain"]

    def stats(v):
        return {"median": statistics.median(v), "mean": statistics.mean(v), "min": min(v), "max": max(v)}

    return {"table": md, "points": len(points), "grid": stats(g), "tin": stats(t), "plain": stats(p),
            "ratio": statistics.mean(t) / statistics.mean(g), "ratio_plain": statistics.mean(p) / statistics.mean(g),
            "ratio_scene": t[0] / g[0], "grid_best_at_scene": g[0] == min(g), "tin_best_at_scene": t[0] == min(t),
            "spread": max(max(g) / min(g), max(t) / min(t)),
            "summary": {"grid": {"accuracy vs analytic references": f"pile {statistics.mean(g):.0f} um"},
                        "tin": {"accuracy vs analytic references": f"pile {statistics.mean(t):.0f} um"}}}
