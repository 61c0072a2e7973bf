#!/usr/bin/python3
"""Stability matrix: every case on every back-end ends as ok, degraded (which metric and how
much), refused (the message) or crashed (never acceptable). A case is a scene plus --set
overrides, or a scene file with a bad value; each run has a time limit."""
import re
from pathlib import Path
from types import SimpleNamespace

import sbrun

BASE = sbrun.DIAGONAL_SCENE
C = sbrun.DOMAIN_SIDE / 2
TIMEOUT_S = 300

# name -> (description, overrides, scene text or None)
CASES = {
    "lattice": ("initial points on a regular lattice (co-circular)",
                ["tin.initial_points=2500", "tin.initial_jitter=0", "terrain.kind=flat"], None),
    "crossing": ("strokes crossing each other",
                 [f"stroke.path_m=[[{C - .08}, {C - .08}], [{C + .08}, {C + .08}], [{C + .08}, {C - .08}], "
                  f"[{C - .08}, {C + .08}]]", "stroke.repeat=2"], None),
    "one_spot": ("1000 stamps at one spot", [f"stroke.path_m=[[{C}, {C}]]", "stroke.repeat=1000"], None),
    "leaving": ("stroke touching and leaving the domain",
                [f"stroke.path_m=[[{C}, {C}], [{2 * C + 0.1}, {C}], [{2 * C + 0.1}, -0.1]]"], None),
    "tiny_tool": ("tool smaller than a cell (r = 1 mm, cell 5 mm)", ["tool.radius_m=0.001"], None),
    "huge_tool": ("tool larger than the domain (r = 1 m)", ["tool.radius_m=1.0", "tool.rim_width_m=0.1"], None),
    "sparse_stamps": ("stamp spacing 10 times the tool size",
                      ["stroke.spacing_m=0.4", f"stroke.path_m=[[0.05, 0.05], [{2 * C - .05}, {2 * C - .05}]]"], None),
    "dense_stamps": ("stamp spacing 0.01 times the tool size", ["stroke.spacing_m=0.0004"], None),
    "near_points": ("stamps 1e-12 m apart",
                    [f"stroke.path_m=[[{C}, {C}], [{C + 1e-11}, {C}]]", "stroke.spacing_m=1e-12"], None),
    "utm_offset": ("coordinates offset by 10^6 m (as in UTM)",
                   ["domain.origin_m=[1000000.0, 1000000.0]",
                    f"stroke.path_m=[[{1e6 + C - .035}, {1e6 + C - .035}], [{1e6 + C + .035}, {1e6 + C + .035}]]"], None),
    "angle_1": ("critical angle 1 degree", ["material.critical_angle_deg=1"], None),
    "angle_85": ("critical angle 85 degrees", ["material.critical_angle_deg=85"], None),
    "overshooting_fraction": ("erosion fraction 1.9, overshooting (monotone only up to 1)",
                              ["material.transfer_fraction=1.9", "output.energy=true"], None),
    "unstable_fraction": ("erosion fraction 3, above its stable limit of 2",
                          ["material.transfer_fraction=3", "output.energy=true"], None),
    "nan_value": ("NaN in the scene file", [], "radius_m = nan"),
    "inf_value": ("infinity in the scene file", [], "radius_m = inf"),
    "empty_path": ("empty stroke path", [], "EMPTY_PATH"),
    "negative_size": ("negative domain size", [], "NEGATIVE_SIZE"),
}


def scene_with(text_marker, folder):
    """The base scene with one bad value written into the file (not through --set), kept with
    the runs (a cluster's nodes must read it)."""
    text = BASE.read_text()
    if text_marker == "EMPTY_PATH":
        text = text.replace("path_m = [[0.31820, 0.31820], [0.38891, 0.38891]]", "path_m = []")
    elif text_marker == "NEGATIVE_SIZE":
        text = text.replace("size_m = [0.70710678, 0.70710678]", "size_m = [-0.7, 0.7]")
    else:
        text = text.replace("radius_m = 0.02", text_marker)
    return sbrun.write_scene(Path(folder) / f"bad-{re.sub(r'[^a-z0-9]+', '_', text_marker.lower())}.toml", text)


def classify(name, backend, proc, summary, run_file):
    """(outcome, reason) from the exit code and the metrics."""
    if proc is None:
        return "crashed", f"no answer within {TIMEOUT_S} s"
    if proc.returncode == 2:
        return "refused", proc.stderr.strip().splitlines()[-1][:160] if proc.stderr.strip() else "exit 2"
    if proc.returncode != 0:
        return "crashed", f"exit {proc.returncode}: {proc.stderr.strip()[-160:]}"
    reasons = []
    nan = [k for k in ("volume_drift_rel", "max_slope_excess_deg") if summary.get(k) is None]  # JSON null: NaN
    if nan:
        reasons.append(f"{', '.join(nan)} not a number")
    drift = abs(summary["volume_drift_rel"] or 0.0)
    if drift > 1e-6:
        reasons.append(f"volume drift {drift:.1e}")
    if (summary["max_slope_excess_deg"] or 0.0) > 1.0:
        reasons.append(f"slope excess {summary['max_slope_excess_deg']:.1f} deg")
    if not summary.get("settled", True):
        reasons.append("not settled")
    if summary.get("energy_rises", 0) > 0:
        reasons.append(f"erosion raised the potential energy in {summary['energy_rises']} steps: oscillation")
    return ("degraded", "; ".join(reasons)) if reasons else ("ok", "")


def run(ctx):
    # Column label -> (back-end, extra overrides). The TIN runs with its default (volume
    # corrected, tin.conserve_volume) and without the correction (as the paper), both explicit.
    columns = {"tin": ("tin", ["tin.conserve_volume=true"]), "tin uncorrected": ("tin", ["tin.conserve_volume=false"]),
               "grid": ("grid", []), "sparse": ("sparse", [])}
    backends = list(columns)
    rows, outcomes = [], {}
    scenes = ctx.runs / "stability" / "scenes"
    scenes.mkdir(parents=True, exist_ok=True)
    cases = {k: v for k, v in CASES.items() if k in ctx.profile.get("stability_cases", CASES)}
    jobs, cells = [], []
    for name, (desc, overrides, bad_text) in cases.items():
        for backend in backends:
            engine, extra = columns[backend]
            scene = scene_with(bad_text, scenes) if bad_text else BASE
            jobs.append((scene, engine, f"stability/{name}-{backend.replace(' ', '_')}", overrides + extra))
            cells.append((name, backend))
    # A failing run is a result here (refused, crashed), so check=False.
    for (name, backend), res in zip(cells, ctx.run_many("stability", jobs, check=False, timeout=TIMEOUT_S)):
        proc = None if res["exit"] is None else SimpleNamespace(returncode=res["exit"], stderr=res["stderr"])
        outcome, reason = classify(name, backend, proc, res["summary"], None)
        outcomes[(name, backend)] = {"outcome": outcome, "reason": reason}
    for name, (desc, _, _) in cases.items():
        rows.append([name, desc] + [outcomes[(name, b)]["outcome"] for b in backends])
    md = ctx.table("stability", ["case", "what", *backends], rows)
    reasons = [[name, b, outcomes[(name, b)]["outcome"], outcomes[(name, b)]["reason"]]
               for name in cases for b in backends if outcomes[(name, b)]["outcome"] != "ok"]
    md_reasons = ctx.table("stability_reasons", ["case", "backend", "outcome", "reason"], reasons)
    crashed = [f"{r[0]} on {r[1]}" for r in reasons if r[2] == "crashed"]
    summary = {}
    for b in ("tin", "grid", "sparse"):
        counts = {o: sum(outcomes[(n, b)]["outcome"] == o for n in cases) for o in ("ok", "degraded", "refused", "crashed")}
        text = ", ".join(f"{n} {o}" for o, n in counts.items() if n)
        summary[b] = {"stability": f"{text} of {len(cases)} cases"}
    return {"table": md, "reasons_table": md_reasons, "crashed": crashed, "cases": len(cases), "summary": summary}


if __name__ == "__main__":
    sbrun.main(run)
