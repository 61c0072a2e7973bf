#!/usr/bin/python3
"""Cliffs: the edges of the envelope where a back-end's cost once exploded (a tool deeper than
the bed, a tool smaller than a cell, a many-sided tool, tiny and shallow critical angles,
footprints with long sides or a far vertex), each run on both back-ends of flat_stroke.toml.
The bar: the TIN within 10x the grid's stroke-and-settle time, settled, volume drift <= 1e-6."""
import sbrun

BASE = sbrun.DIAGONAL_SCENE
# A 2 cm square with a 0.2 m spike: ahead (along the motion, x) or sideways (y).
SPIKE_AHEAD = "[[-0.01, -0.01], [0.01, -0.01], [0.2, 0.0], [0.01, 0.01], [-0.01, 0.01]]"
SPIKE_SIDEWAYS = "[[-0.01, -0.01], [0.01, -0.01], [0.01, 0.01], [0.0, 0.2], [-0.01, 0.01]]"

# name -> (what, overrides, needs the disk's keys removed)
CLIFFS = {
    "deep_0.2": ("tool 0.2 m deep, the bed 0.1 m", ["tool.depth_m=0.2"], False),
    "deep_5": ("tool 5 m deep", ["tool.depth_m=5"], False),
    "sides_4096": ("a 4096-sided disk", ["tool.sides=4096"], False),
    "angle_5": ("critical angle 5 degrees", ["material.critical_angle_deg=5"], False),
    "angle_1e-6": ("critical angle 1e-6 degrees", ["material.critical_angle_deg=1e-6"], False),
    "box_0.4mm": ("a 0.4 mm box (below one grid cell)", ["tool.shape=box", "tool.size_m=[0.0004, 0.0004]"], True),
    # Just wider than the TIN's uncut footprints (a quarter of tin.refine_m, 1.7 mm here): cut in.
    "box_2mm": ("a 2 mm box (the narrowest the TIN cuts in)", ["tool.shape=box", "tool.size_m=[0.002, 0.002]"], True),
    "blade_sideways": ("a 10 x 60 mm box swept sideways (a blade)", ["tool.shape=box", "tool.size_m=[0.01, 0.06]"],
                       True),
    "spike_ahead": ("a 0.2 m spike pointing along the motion",
                    ["tool.shape=polygon", "tool.polygon_m=" + SPIKE_AHEAD], True),
    "spike_sideways": ("a 0.2 m spike swept sideways",
                       ["tool.shape=polygon", "tool.polygon_m=" + SPIKE_SIDEWAYS], True),
}


# Runs per cliff and back-end, interleaved: the table gives each back-end's median time.
REPEATS = 5


def footprint_scene(folder):
    """flat_stroke.toml without the disk's keys (radius, sides), kept with the runs."""
    lines = [ln for ln in BASE.read_text().splitlines() if not ln.startswith(("radius_m", "sides"))]
    return sbrun.write_scene(folder / "flat_stroke_footprint.toml", "\n".join(lines) + "\n")


def stroke_and_settle_s(summary):
    return summary["time_s.total"] + summary.get("time_s.relax", 0.0)


def run(ctx):
    scenes = ctx.runs / "cliffs" / "scenes"
    scenes.mkdir(parents=True, exist_ok=True)
    cliffs = {k: v for k, v in CLIFFS.items() if k in ctx.profile.get("cliffs", CLIFFS)}
    repeats = ctx.profile.get("cliff_repeats", REPEATS)
    jobs = []
    for name, (_, overrides, footprint) in cliffs.items():
        scene = footprint_scene(scenes) if footprint else BASE
        jobs += [(scene, backend, f"cliffs/{name}-{backend}-{r}", overrides)
                 for r in range(repeats) for backend in ("tin", "grid")]
    summaries = ctx.run_many("cliffs", jobs)
    rows, missed = [], []
    for k, (name, (what, _, _)) in enumerate(cliffs.items()):
        runs = summaries[2 * repeats * k:2 * repeats * (k + 1)]
        # The run of median time per back-end (the runs differ in their timings only).
        tin = sorted(runs[0::2], key=stroke_and_settle_s)[repeats // 2]
        grid = sorted(runs[1::2], key=stroke_and_settle_s)[repeats // 2]
        ratio = stroke_and_settle_s(tin) / max(stroke_and_settle_s(grid), 1e-9)
        ok = ratio <= 10.0 and tin["settled"] and abs(tin["volume_drift_rel"]) <= 1e-6
        if not ok:
            missed.append(name)
        rows.append([name, what, stroke_and_settle_s(tin), stroke_and_settle_s(grid), f"{ratio:.1f}x",
                     tin["relax_updates"], grid["relax_updates"], tin["vertices"],
                     "yes" if tin["settled"] else "NO", "yes" if grid["settled"] else "NO",
                     f"{tin['volume_drift_rel']:.1e}", f"{grid['volume_drift_rel']:.1e}", "yes" if ok else "no"])
    md = ctx.table("cliffs", ["cliff", "what", "tin s", "grid s", "time tin / grid", "tin settling updates",
                              "grid settling updates", "tin vertices", "tin settled", "grid settled", "tin drift",
                              "grid drift", "within the bar (time ratio too)"], rows)
    ratios = {r[0]: float(r[4].rstrip("x")) for r in rows}
    worst = max(ratios, key=ratios.get)
    return {"table": md, "repeats": repeats, "within": len(cliffs) - len(missed), "cliffs": len(cliffs),
            "missed": missed, "worst": worst, "worst_ratio": ratios[worst],
            "worst_small": worst.startswith(("box", "spike", "blade"))}


if __name__ == "__main__":
    sbrun.main(run)
