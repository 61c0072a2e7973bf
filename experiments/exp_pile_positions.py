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
    return f"""## The poured pile at several pour points

`pile.toml` pours at the domain's centre: a node of the 2.5 mm grid and a point of the TIN's first
diagonal, special points for both. The same 20 pours at {len(points)} points within two grid
cells of it (the scene's and a Halton sequence), each back-end as the scene asks:

{md}
- RMSE against the analytic cone, grid: median {statistics.median(g):.1f} um, mean {statistics.mean(g):.1f},
  {min(g):.1f}-{max(g):.1f}; TIN: median {statistics.median(t):.1f} um, mean {statistics.mean(t):.1f},
  {min(t):.1f}-{max(t):.1f}. Ratio of the means {statistics.mean(t) / statistics.mean(g):.2f}; at the scene's point
  {t[0] / g[0]:.2f}. The TIN without the scene's curvature refinement at rest (`tin.curvature_tolerance_m = 0`):
  median {statistics.median(p):.1f} um, mean {statistics.mean(p):.1f}, ratio of the means
  {statistics.mean(p) / statistics.mean(g):.2f}.
- The scene's point is {"the grid's best" if g[0] == min(g) else "not the grid's best"} and {"the TIN's best" if t[0] == min(t) else "not the TIN's best"} of these:
  single points differ by up to {max(max(g) / min(g), max(t) / min(t)):.1f}x within a model, so accuracy
  claims on the pile should rest on the distribution, not on `pile.toml` alone.
"""
