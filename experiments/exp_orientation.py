#!/usr/bin/python3
"""Accuracy at any orientation: a trench dug at azimuths from 0 to 90 degrees (not
only multiples of 45), a straight ridge poured at several azimuths, a plane tilted above the
critical angle falling toward several azimuths, and the pile -- with both erosion rules (`edge`,
the paper's per-neighbour test; `gradient`, the isotropic one) on the TIN, the grid with 4 and
8 neighbours and the sparse grid. Every run names its rule, so results never depend on the
default. Tables: every case (orientation_cases), the trench's wall angles per azimuth
(orientation_trench) and the worst case over orientations per back-end and rule
(orientation_worst); a chart of the angles against azimuth."""
import math

import sbrun

CRITICAL = 30.0  # material.critical_angle_deg of every scene used here
RULES = ["edge", "gradient"]
# label -> (back-end, overrides); the sparse grid runs the dense grid's kernel (same heights),
# so its rows show the price of its storage, not another accuracy.
# "tin curved": the TIN with curvature refinement (tin.curvature_tolerance_m = 0.2 mm), its way
# to trade step time for accuracy (README, scene keys).
CURVED = "tin curved"
CONFIGS = {"tin": ("tin", []), CURVED: ("tin", ["tin.curvature_tolerance_m=0.0002"]),
           "grid 4-nb": ("grid", ["grid.neighbours=4"]), "grid 8-nb": ("grid", ["grid.neighbours=8"]),
           "sparse 8-nb": ("sparse", ["grid.neighbours=8"])}
NOT_CURVED = [c for c in CONFIGS if c != CURVED]
# Scene, what its azimuth turns, and the summary keys of (mean, max, min, spread, worst |error|).
CASES = {
    "trench": ("trench_azimuth.toml", ("trench.wall_angle_mean_deg", "trench.wall_angle_deg",
                                       "trench.wall_angle_min_deg", "trench.wall_angle_spread_deg",
                                       "trench.wall_worst_error_deg")),
    "ridge": ("ridge.toml", ("ridge.flank_angle_mean_deg", "ridge.flank_angle_deg", "ridge.flank_angle_min_deg",
                             "ridge.flank_angle_spread_deg", "ridge.flank_worst_error_deg")),
    # The plane: local slopes (mean, steepest) and the fitted plane's slope (as "min" column: see case_row).
    "plane": ("plane.toml", ("plane.slope_mean_deg", "plane.slope_max_deg", None, None, None)),
}
TRENCH_ALL = [0, 10, 22.5, 30, 45, 60, 67.5, 80, 90]
# Per profile: case -> (azimuths in degrees, configurations); the tiny one is the smoke test's.
# COST is what the driver announces, an order of magnitude (the TIN planes are the longest runs).
PLAN = {
    "tiny": {"trench": ([0, 22.5], ["tin", "grid 8-nb"]), "ridge": ([22.5], ["tin", "grid 8-nb"]),
             "plane": ([22.5], ["grid 8-nb"]), "pile": ([0], ["tin", "grid 8-nb"])},
    "paper": {"trench": (TRENCH_ALL, list(CONFIGS)), "ridge": ([0, 22.5, 45, 67.5], list(CONFIGS)),
              "plane": ([0, 22.5, 45, 67.5], NOT_CURVED), "pile": ([0], list(CONFIGS))},
    "full": {"trench": (sorted(set(range(0, 91, 5)) | {22.5, 67.5}), list(CONFIGS)),
             "ridge": (TRENCH_ALL, list(CONFIGS)), "plane": (TRENCH_ALL, NOT_CURVED), "pile": ([0], list(CONFIGS))},
}
COST = {"tiny": "a few CPU-seconds", "paper": "about 40 CPU-seconds", "full": "about 2 CPU-minutes"}
CENTRE = 0.15  # trench_azimuth.toml and ridge.toml: a 0.3 m square


def stroke_at(azimuth_deg, half_length_m):
    """A straight stroke through the centre of the 0.3 m square, turned to AZIMUTH_DEG from +x."""
    a = math.radians(azimuth_deg)
    dx, dy = half_length_m * math.cos(a), half_length_m * math.sin(a)
    return (f"stroke.path_m=[[{CENTRE - dx:.6f}, {CENTRE - dy:.6f}], "
            f"[{CENTRE + dx:.6f}, {CENTRE + dy:.6f}]]")


def turned(case, azimuth_deg):
    """The overrides that turn CASE to AZIMUTH_DEG (the trench 0.24 m long, the ridge 0.2 m)."""
    if case == "trench":
        return [stroke_at(azimuth_deg, 0.12)]
    if case == "ridge":
        return [stroke_at(azimuth_deg, 0.10)]
    if case == "plane":
        return [f"terrain.azimuth_deg={azimuth_deg:g}"]
    return []


def cases(profile_name):
    """(case, azimuth, config, rule) of every run of the profile, in a fixed order."""
    out = []
    for case, (azimuths, configs) in PLAN[profile_name].items():
        out += [(case, az, cfg, rule) for az in azimuths for cfg in configs for rule in RULES]
    return out


def job(case, az, cfg, rule):
    scene = "pile.toml" if case == "pile" else CASES[case][0]
    backend, extra = CONFIGS[cfg]
    if case == "pile" and backend == "tin":  # without pile.toml's own curvature refinement at rest
        extra = extra + (["tin.curvature_when=always"] if cfg == CURVED else [sbrun.NO_CURVATURE])
    name = f"orientation/{case}-{az:g}-{cfg.replace(' ', '_').replace('-', '')}-{rule}"
    return (sbrun.SCENES / scene, backend, name, extra + turned(case, az) + [f"erosion.rule={rule}"])


_announced = set()


def settled_text(r):
    """A run that did not settle is measured all the same, and says so (its angles are those of a
    surface still moving)."""
    return "yes" if r["settled"] else f"no (max slope {r['max_slope_deg']:.1f} deg)"


def case_row(case, az, cfg, rule, r):
    """One run's row of orientation_cases."""
    if case == "pile":
        flank = r["pile.flank_angle_deg"]
        return [case, az, cfg, rule, flank, "", "", "", abs(flank - CRITICAL), r["pile.roundness"],
                r["step_ms.p50"], r["volume_drift_rel"], settled_text(r)]
    mean_k, max_k, min_k, spread_k, worst_k = CASES[case][1]
    if case == "plane":  # the fitted plane's slope where the others have their gentlest section
        worst = max(abs(r["plane.slope_deg"] - CRITICAL), abs(r[max_k] - CRITICAL))
        return [case, az, cfg, rule, r[mean_k], r[max_k], r["plane.slope_deg"], "", worst, "",
                r["step_ms.p50"], r["volume_drift_rel"], settled_text(r)]
    return [case, az, cfg, rule, r[mean_k], r[max_k], r[min_k], r[spread_k], r[worst_k], "",
            r["step_ms.p50"], r["volume_drift_rel"], settled_text(r)]


def trench_table(ctx, s, plan):
    """The trench's walls per azimuth: mean / steepest section, one column per model and rule."""
    t_az, t_cfg = plan["trench"]
    columns = [(cfg, rule) for cfg in t_cfg for rule in RULES if not cfg.startswith("sparse")]
    rows = [[az] + [f"{s[('trench', az, cfg, rule)]['trench.wall_angle_mean_deg']:.2f} / "
                    f"{s[('trench', az, cfg, rule)]['trench.wall_angle_deg']:.2f}" for cfg, rule in columns]
            for az in t_az]
    return ctx.table("orientation_trench", ["azimuth deg"] + [f"{cfg} {rule}" for cfg, rule in columns], rows)


# The bar every model and rule is judged against: trench mean within 0.3 degree and every section
# within 0.6 at every azimuth, pile flank within 0.5; roundness at most 0.02 (TIN and 8 neighbours).
BAR = {"trench_mean": 0.3, "trench_section": 0.6, "pile_flank": 0.5, "roundness": 0.02}


def worst_row(s, plan, cfg, rule):
    """The worst case over orientations of one model and rule, and whether it meets BAR."""
    def worst(case, key, of=lambda v: abs(v - CRITICAL)):
        """(largest of(value), its azimuth) over the case's azimuths; ("", "") if not run."""
        vals = [(of(s[(case, az, cfg, rule)][key]), az) for az in plan[case][0] if (case, az, cfg, rule) in s]
        return max(vals) if vals else ("", "")

    tm, tma = worst("trench", "trench.wall_angle_mean_deg")
    tw, twa = worst("trench", "trench.wall_worst_error_deg", of=lambda v: v)
    rm, _ = worst("ridge", "ridge.flank_angle_mean_deg")
    rw, _ = worst("ridge", "ridge.flank_worst_error_deg", of=lambda v: v)
    pf, pfa = worst("plane", "plane.slope_deg")
    pm, _ = worst("plane", "plane.slope_max_deg", of=lambda v: v)
    pile = s.get(("pile", 0, cfg, rule))
    flank = pile["pile.flank_angle_deg"] if pile else ""
    roundness = pile["pile.roundness"] if pile else ""
    runs = [r for (c, _, m, ru), r in s.items() if m == cfg and ru == rule]
    unsettled = sum(not r["settled"] for r in runs)
    checks = [tm != "" and tm <= BAR["trench_mean"], tw != "" and tw <= BAR["trench_section"], unsettled == 0]
    if pile:
        checks.append(abs(flank - CRITICAL) <= BAR["pile_flank"])
        if cfg != "grid 4-nb":
            checks.append(roundness <= BAR["roundness"])
    t_az = plan["trench"][0]
    trench_ms = [s[("trench", az, cfg, rule)]["step_ms.p50"] for az in t_az if ("trench", az, cfg, rule) in s]
    return [cfg, rule, tm, tma, tw, twa, rm, rw, pf, pfa, pm, flank, roundness,
            sorted(trench_ms)[len(trench_ms) // 2] if trench_ms else "",
            f"{len(runs) - unsettled}/{len(runs)}", "yes" if all(checks) else "no"]


WORST_HEADERS = ["model", "rule", "trench mean error deg", "at azimuth", "trench worst section deg", "at azimuth",
                 "ridge mean error deg", "ridge worst section deg", "plane fit error deg", "at azimuth",
                 "plane steepest local deg", "pile flank deg", "pile roundness", "trench step ms p50",
                 "runs settled", "meets the bar"]


def angle_chart(ctx, s, plan):
    """Angles against azimuth: one line per model (colour) and rule (dashed: edge; solid: gradient)."""
    import matplotlib.pyplot as plt

    colours = {"tin": "C3", CURVED: "C4", "grid 4-nb": "C1", "grid 8-nb": "C0"}
    panels = [("trench", "trench.wall_angle_mean_deg", "trench walls, mean of the sections"),
              ("trench", "trench.wall_angle_deg", "trench walls, steepest section"),
              ("ridge", "ridge.flank_angle_mean_deg", "ridge flanks, mean of the sections"),
              ("plane", "plane.slope_deg", "tilted plane, fitted slope")]
    fig, axes = plt.subplots(1, len(panels), figsize=(4.6 * len(panels), 4.0), sharey=True)
    for ax, (case, key, title) in zip(axes, panels):
        azimuths, cfgs = plan[case]
        for cfg in cfgs:
            if cfg not in colours:
                continue
            for rule in RULES:
                if (case, azimuths[0], cfg, rule) not in s:
                    continue
                ys = [s[(case, az, cfg, rule)][key] for az in azimuths]
                ax.plot(azimuths, ys, color=colours[cfg], ls="--" if rule == "edge" else "-",
                        marker="o" if rule == "gradient" else "x", ms=4, label=f"{cfg} {rule}")
        ax.axhline(CRITICAL, color="k", lw=0.8)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("azimuth [deg from +x]")
        ax.set_xticks([0, 22.5, 45, 67.5, 90], ["0", "22.5", "45", "67.5", "90"])
        ax.set_xlim(-3, 93)
    axes[0].set_ylabel("angle [deg] (critical 30)")
    axes[0].legend(fontsize=7)
    return ctx.figure(fig, "orientation")


def too_flat(s):
    """Where a rule leaves a surface flatter than critical by more than half a degree (pile, plane)."""
    out = set()
    for (case, az, cfg, rule), r in s.items():
        key = {"pile": "pile.flank_angle_deg", "plane": "plane.slope_deg"}.get(case)
        if key and r[key] < CRITICAL - 0.5:
            out.add(f"{cfg} {rule} ({case} {r[key]:.2f}{'' if case == 'pile' else f' at {az:g} deg'})")
    return sorted(out)


def run(ctx):
    index = cases(ctx.profile_name)
    if ctx.profile_name not in _announced:  # the driver calls run() once per round
        _announced.add(ctx.profile_name)
        sbrun.progress(f"  orientation: {len(index)} runs in the {ctx.profile_name} profile "
                       f"({COST[ctx.profile_name]})")
    s = dict(zip(index, ctx.run_many("orientation", [job(*c) for c in index])))
    plan = PLAN[ctx.profile_name]
    ctx.table("orientation_cases", ["case", "azimuth deg", "model", "rule", "mean deg", "max deg",
                                    "min deg (plane: fitted)", "spread deg", "worst error deg", "roundness",
                                    "step ms p50", "drift rel", "settled"],
              [case_row(*k, r) for k, r in s.items()])
    trench_md = trench_table(ctx, s, plan)
    worst_rows = [worst_row(s, plan, cfg, rule) for cfg in CONFIGS for rule in RULES
                  if any(c == cfg for _, _, c, _ in index)]
    worst_md = ctx.table("orientation_worst", WORST_HEADERS, worst_rows)
    png = angle_chart(ctx, s, plan)

    def span(rule, col):
        vals = [r[col] for r in worst_rows if r[1] == rule and r[col] != ""]
        return max(vals) if vals else float("nan")

    spans = {rule: {"trench_mean": span(rule, 2), "trench_section": span(rule, 4), "plane": span(rule, 8)}
             for rule in RULES}
    still = [f"{cfg} at {az:g} deg" for case, az, cfg, rule in s if case == "plane" and rule == "edge"
             and s[(case, az, cfg, rule)]["plane.slope_deg"] > CRITICAL + 4.9]
    meets = [f"{r[0]} with the {r[1]} rule" for rule in RULES for r in worst_rows if r[1] == rule and r[-1] == "yes"]
    summary = {}
    for r in worst_rows:
        if r[1] == "gradient" and r[4] != "":
            label = {"grid 8-nb": "grid", "sparse 8-nb": "sparse", "grid 4-nb": "grid 4-nb"}.get(r[0], r[0])
            summary[label] = {"accuracy vs analytic references": f"trench worst section {r[4]:.2f} deg"}
    return {"trench_table": trench_md, "worst_table": worst_md, "png": png, "spans": spans, "still": still,
            "flat": too_flat(s)[:4], "flat_count": len(too_flat(s)), "meets": meets, "bar": BAR, "trench_azimuths": plan["trench"][0],
            "ridge_azimuths": plan["ridge"][0], "plane_azimuths": plan["plane"][0], "summary": summary}


if __name__ == "__main__":
    sbrun.main(run)
