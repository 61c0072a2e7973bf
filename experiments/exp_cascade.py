#!/usr/bin/python3
"""The settling cascade, speed against accuracy. Both back-ends start their settling with a
coarse-to-fine cascade (grid/multires_settle.hpp, tin/settle_cascade.hpp; erosion.cascade): sand moves
over long distances on coarse levels, each level's change added to its members as a constant. On a pile
poured at a point and spreading over many cells, those constants throw sand past where the fine rule
would have left it, and the rule, which only moves sand downhill, never takes it back: the pile ends
wider and flatter. This table sets the time the cascade saves against the accuracy it costs: the poured
pile at resolutions where it spans many elements, each with the cascade and with the fine rule alone,
and the deep stroke (flat_stroke.toml with a tool deeper than the bed), the disturbance it is for."""
import sbrun

GRID_CELLS = {"tiny": [0.002], "paper": [0.002, 0.001, 0.0005], "full": [0.002, 0.001, 0.0005, 0.00025]}
TIN_POINTS = {"tiny": [10000], "paper": [10000, 100000], "full": [10000, 100000, 1000000]}
DEEP = ["tool.depth_m=0.2"]


def cases(profile_name):
    """(case, scene, backend, resolution, overrides) without the cascade's setting."""
    out = [("poured pile", "pile.toml", "grid", f"{c * 1e3:g} mm cells", [f"grid.cell_m={c}"])
           for c in GRID_CELLS[profile_name]]
    # Without pile.toml's curvature refinement at rest, with which the TIN's cascade stands aside.
    out += [("poured pile", "pile.toml", "tin", f"{n} initial points", [f"tin.initial_points={n}", sbrun.NO_CURVATURE])
            for n in TIN_POINTS[profile_name]]
    if profile_name != "tiny":  # refined where the sand flows only, to 2 mm
        out.append(("poured pile", "pile.toml", "tin", "refined to 2 mm", ["tin.refine_m=0.002", sbrun.NO_CURVATURE]))
    out += [("deep stroke", "flat_stroke.toml", backend, "scene's", DEEP) for backend in ("grid", "tin")]
    return out


def run(ctx):
    import matplotlib.pyplot as plt

    todo = cases(ctx.profile_name)
    jobs = [(sbrun.SCENES / scene, backend, f"cascade/{sbrun.slug(case)}-{backend}-{sbrun.slug(res)}-{on}",
             overrides + [f"erosion.cascade={on}"])
            for case, scene, backend, res, overrides in todo for on in ("true", "false")]
    s = ctx.run_many("cascade", jobs)

    rows, pairs = [], []
    for k, (case, _, backend, res, _) in enumerate(todo):
        on, off = s[2 * k], s[2 * k + 1]
        pairs.append((case, backend, res, on, off))
        for label, r in (("on", on), ("off", off)):
            rmse = r.get("reference.rmse_m")
            rows.append([case, backend, res, label, r["vertices"] or r["cells"], r["time_s.relax"], r["relax_updates"],
                         "" if rmse is None else rmse * 1e6, r.get("pile.flank_angle_deg", ""),
                         r.get("pile.roundness", ""), r["max_slope_excess_deg"], "yes" if r["settled"] else "no"])
    md = ctx.table("cascade", ["case", "back-end", "resolution", "cascade", "elements", "settling s",
                               "settling updates", "RMSE um", "flank deg", "roundness", "slope excess deg",
                               "settled"], rows)

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for case, backend, res, on, off in pairs:
        if on.get("reference.rmse_m") is None:
            continue
        xs = [max(on["time_s.relax"], 1e-4), max(off["time_s.relax"], 1e-4)]
        ys = [on["reference.rmse_m"] * 1e6, off["reference.rmse_m"] * 1e6]
        line, = ax.plot(xs, ys, "-", lw=0.8)
        ax.plot(xs[0], ys[0], "o", color=line.get_color(), label=f"{backend}, {res}")
        ax.plot(xs[1], ys[1], "s", color=line.get_color(), mfc="none")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("settling time [s] (filled: cascade on; open: fine rule alone)")
    ax.set_ylabel("pile RMSE against the 30 deg cone [um]")
    ax.set_title("The settling cascade: time saved against accuracy lost", fontsize=10)
    ax.legend(fontsize=7)
    png = ctx.figure(fig, "cascade")

    def both(on, off):
        return {"rmse_on": on.get("reference.rmse_m", float("nan")) * 1e6,
                "rmse_off": off.get("reference.rmse_m", float("nan")) * 1e6,
                "flank_on": on.get("pile.flank_angle_deg", float("nan")),
                "flank_off": off.get("pile.flank_angle_deg", float("nan")), "s_on": on["time_s.relax"],
                "s_off": off["time_s.relax"], "updates_on": on["relax_updates"], "updates_off": off["relax_updates"]}

    piles = [dict(backend=b, res=res, **both(on, off)) for case, b, res, on, off in pairs if case == "poured pile"]
    deep = [dict(backend=b, **both(on, off)) for case, b, _, on, off in pairs if case == "deep stroke"]
    worse = [f"{p['backend']} {p['res']}" for p in piles if p["rmse_on"] > 1.2 * p["rmse_off"]]
    rmse_ratio = [p["rmse_on"] / p["rmse_off"] for p in piles if p["rmse_off"] > 0]
    return {"png": png, "table": md, "piles": len(piles), "deep": deep, "worse": worse,
            "rmse_ratio_min": min(rmse_ratio, default=float("nan")), "rmse_ratio_max": max(rmse_ratio, default=float("nan"))}
