#!/usr/bin/python3
"""Against particle sand: every back-end on the scenes of the particle (DEM) references
(experiments/dem/references/, written by `make dem`), compared with the grains' surfaces.

For each case the back-ends run the very scene the particles ran; a stroke case also runs
with `erosion.relax_at_end = false`, the surface as the last stamp left it, beside the
particles' surface with the tool still in. Both sides are measured by particle_metrics.py on
their own rasters (the particles' upper envelope, averaged over seeds, and the run file's
comparison raster): the cross-section averaged over the middle of the stroke (floor, berm
crests and their distance from the tool's edge, walls, cut and berm areas), the pile ahead of
the tool, the section's and the whole surface's RMSE against the particles' mean; a pour case
its height, flank, foot radius and volume. The particles' figures are given as the mean and the
standard deviation over their seeds.

How much of a back-end's distance from the particles is the shared model and how much its
discretisation: the back-ends' distance from each other bounds the discretisation's share.

The tool's force: the particles' trajectory is replayed through `sandbench interactive` on every
back-end, and the haptic force model's parameters are fitted to the particles' force on those
replays (haptic_calibration.py).
"""
import math
import sys
from pathlib import Path

import numpy as np

import particle_metrics as pm
import haptic_calibration
import sbrun

sys.path.insert(0, str(Path(__file__).resolve().parent / "dem"))
import reference_file  # noqa: E402

BACKENDS = ("grid", "sparse", "tin")
DISPLACEMENTS = ("rim", "bulldoze", "carry")  # tool.displacement: every back-end runs with each
# Variants of the default model that every back-end also runs with: name, the keys they set.
# `deflect`: its front sends sand round the tool at the particles' own tool friction
# (tool.face_friction, common/front_pile.hpp), which the default leaves infinite.
VARIANTS = {"deflect": ("tool.face_friction=0.5",)}
REFERENCES = sbrun.ROOT / "experiments" / "dem" / "references"
STROKE_ROWS = [("floor_m", "trench floor, mm", 1e3), ("crest_left_m", "left crest, mm", 1e3),
               ("crest_right_m", "right crest, mm", 1e3), ("crest_left_from_edge_m", "left crest from tool edge, mm", 1e3),
               ("crest_right_from_edge_m", "right crest from tool edge, mm", 1e3),
               ("wall_left_deg", "left wall, deg", 1), ("wall_right_deg", "right wall, deg", 1),
               ("cut_area_m2", "cut area, cm2", 1e4), ("berm_area_m2", "berm area, cm2", 1e4),
               ("berm_cut_ratio", "berm / cut", 1), ("ahead_height_m", "pile ahead, mm", 1e3),
               ("ahead_volume_m3", "pile ahead, cm3", 1e6), ("section_rmse_m", "section RMSE, mm", 1e3),
               ("surface_rmse_m", "surface RMSE, mm", 1e3)]
PILE_ROWS = [("height_m", "height, mm", 1e3), ("flank_deg", "flank, deg", 1), ("radius_m", "foot radius, mm", 1e3),
             ("volume_m3", "volume, cm3", 1e6), ("surface_rmse_m", "surface RMSE, mm", 1e3)]


def load_references():
    refs = [reference_file.Reference(p) for p in sorted(REFERENCES.glob("*.h5"))]
    POURS.update(r.case for r in refs if scene_of(r)["tool"].get("shape") == "pour")
    return refs


def scene_of(ref):
    import tomllib
    return tomllib.loads((sbrun.ROOT / ref.scene).read_text())


def stroke_of(scene):
    tool = scene["tool"]
    if tool.get("shape", "disk") == "box":
        half_length, half_width = tool["size_m"][0] / 2, tool["size_m"][1] / 2
    else:
        half_length = half_width = tool["radius_m"]
    return pm.Stroke(scene["stroke"]["path_m"], half_length, half_width, scene["terrain"]["height_m"])


def raster_of(path, lattice):
    """A run file's final raster, resampled onto the reference's lattice when it differs."""
    with sbrun.read_h5(path) as f:
        z = f["final/raster"][()]
        origin = tuple(f["final/raster"].attrs["origin_m"])
        spacing = float(f["final/raster"].attrs["spacing_m"])
    if z.shape == (lattice.ny, lattice.nx) and np.allclose(origin, lattice.origin) and \
            math.isclose(spacing, lattice.spacing):
        return z
    own = pm.Lattice(origin, spacing, z.shape)
    X, Y = lattice.node_xy()
    return own.sample(z, X, Y)


def measure(scene, lattice, surface, reference_mean, reference_section=None):
    """The case's metrics of one surface, with its RMSE against the particles' mean."""
    if scene["tool"].get("shape") == "pour":
        out = pm.pile_metrics(lattice, surface, scene["stroke"]["path_m"][0], scene["terrain"]["height_m"])
    else:
        out = pm.stroke_metrics(lattice, surface, stroke_of(scene))
        if reference_section is not None:
            out["section_rmse_m"] = pm.rmse(out["section_z_m"], reference_section)
    out["surface_rmse_m"] = pm.rmse(surface, reference_mean)
    return out


def spread(values):
    v = np.asarray([x for x in values if not math.isnan(x)])
    return (float(v.mean()), float(v.std())) if len(v) else (math.nan, math.nan)


def case_rows(ref, scene, lattice, stage, backend_surfaces):
    """Rows of the case's table at one stage: the particles (mean, sd over seeds), each back-end."""
    mean = ref.mean(stage)
    is_pour = scene["tool"].get("shape") == "pour"
    base = None if is_pour else pm.stroke_metrics(lattice, mean, stroke_of(scene))["section_z_m"]
    seeds = [measure(scene, lattice, s, mean, base) for s in ref.surfaces[stage]]
    rows = PILE_ROWS if is_pour else STROKE_ROWS
    backends = {b: measure(scene, lattice, z, mean, base) for b, z in backend_surfaces.items()}
    table = []
    for key, label, scale in rows:
        m, sd = spread([s[key] * scale for s in seeds])
        table.append([label, f"{m:.3g} ± {sd:.2g}"] + [float(f"{backends[b][key] * scale:.3g}") for b in backend_surfaces])
    return table, seeds, backends, base


def dilation(ref, scene, lattice):
    """The particles' bulk volume change over the stroke, relative to the volume the tool cut."""
    if scene["tool"].get("shape") == "pour":
        return math.nan
    out = []
    for initial, final in zip(ref.surfaces["initial"], ref.surfaces["final"]):
        change = float((final - initial).sum()) * lattice.spacing ** 2
        cut = pm.stroke_metrics(lattice, final, stroke_of(scene))["cut_area_m2"]
        out.append(change / (cut * stroke_of(scene).length) if cut > 0 else math.nan)
    return spread(out)


def section_figure(ctx, cases, names):
    import matplotlib.pyplot as plt
    strokes = [c for c in cases if c["sections"]]
    fig, axes = plt.subplots(len(strokes), 1, figsize=(7.5, 3.2 * len(strokes)), squeeze=False)
    for ax, c in zip(axes[:, 0], strokes):
        u = c["sections"]["u"] * 1e3
        seeds = np.array(c["sections"]["seeds"]) * 1e3
        ax.fill_between(u, seeds.min(axis=0), seeds.max(axis=0), color="0.75", label="particles (seeds' range)")
        ax.plot(u, seeds.mean(axis=0), color="k", lw=1.5, label="particles (mean)")
        for label in names:
            b = label.split()[0]
            colour = {"grid": "C0", "sparse": "C2", "tin": "C3"}[b]
            model = label.split()[1] if " " in label else None  # None: the default
            style = {None: "--" if b == "sparse" else "-", "rim": ":"}.get(model, "-.")
            ax.plot(u, np.asarray(c["sections"]["backends"][label]) * 1e3, color=colour, lw=1.2, ls=style, label=label)
        ax.axhline(0, color="0.5", lw=0.5)
        ax.set_title(f"{c['case']}: cross-section averaged over {pm.SECTION_BAND[0]:.0%}-{pm.SECTION_BAND[1]:.0%} "
                     f"of the stroke, after the tool lifted", fontsize=9)
        ax.set_xlabel("across the stroke, mm")
        ax.set_ylabel("height above the bed, mm")
        ax.legend(fontsize=7)
    fig.tight_layout()
    return ctx.figure(fig, "particles_sections")


def difference_figure(ctx, cases):
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(cases), len(BACKENDS), figsize=(3.6 * len(BACKENDS), 3.0 * len(cases)),
                             squeeze=False)
    for row, c in zip(axes, cases):
        for ax, b in zip(row, BACKENDS):
            d = (c["surfaces"][b] - c["mean"]) * 1e3
            lim = max(1.0, float(np.percentile(np.abs(d), 99)))
            im = ax.imshow(d, origin="lower", cmap="RdBu_r", vmin=-lim, vmax=lim,
                           extent=[c["x"][0], c["x"][-1], c["y"][0], c["y"][-1]])
            ax.set_title(f"{c['case']}: {b} - particles", fontsize=8)
            ax.tick_params(labelsize=6)
            fig.colorbar(im, ax=ax, shrink=0.8).set_label("mm", fontsize=7)
    fig.tight_layout()
    return ctx.figure(fig, "particles_difference")


def speed_figure(ctx, cases, names):
    """Cost against distance from the particles: CPU seconds of the stroke (the particles: LAMMPS's
    stroke stage; a back-end: its stroke and settling) against the section RMSE."""
    import matplotlib.pyplot as plt
    strokes = [c for c in cases if c["sections"]]
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for c, marker in zip(strokes, "os^D"):
        for label in names:
            colour = {"grid": "C0", "sparse": "C2", "tin": "C3"}[label.split()[0]]
            ax.scatter(c["cost_s"][label], c["backends"][label]["section_rmse_m"] * 1e3, color=colour, marker=marker,
                       facecolors="none" if " " in label else colour, label=f"{label}, {c['case']}")
        ax.scatter(c["dem_cost_s"], c["dem_self_rmse_m"] * 1e3, color="k", marker=marker,
                   label=f"particles, {c['case']} (their seeds' spread)")
    ax.set_xscale("log")
    ax.set_xlabel("CPU seconds for the stroke (one core)")
    ax.set_ylabel("section RMSE against the particles' mean, mm")
    ax.legend(fontsize=6)
    return ctx.figure(fig, "particles_speed_accuracy")


POURS = set()  # cases whose tool is a pour, filled by load_references


def run_name(ref, label):
    """The run behind a case's label: a pour's runs are the default model's whatever the label."""
    if ref.case in POURS:
        label = label.split()[0]
    return f"particles/{ref.case}-{label.replace(' ', '-')}"


def key_default(ctx, key):
    """A scene key's default as the binary's validator states it (a string: `"rim"`, `800`)."""
    for line in ctx.sandbench_cmd("scene-keys").splitlines():
        if line.startswith(key + " "):
            return line.split(", default ", 1)[1].rsplit(", allowed ", 1)[0]
    raise RuntimeError(f"sandbench scene-keys lists no {key}")


def default_displacement(ctx):
    """The scenes' default `tool.displacement`."""
    return key_default(ctx, "tool.displacement").strip('"')


def force_parameters(ctx, scene):
    """The haptic force model's (k, b, mu) of a scene: its [material] keys, else their defaults."""
    keys = ("stiffness_n_per_m", "drag_n_s_per_m", "friction")
    material = scene.get("material", {})
    return tuple(float(material.get(k, key_default(ctx, f"material.{k}"))) for k in keys)


def variants(default):
    """Labels and overrides: each back-end with the default model, then with each other one; and
    the model the report sets beside the default (the paper's rim, unless that is the default)."""
    models = {d: (f"tool.displacement={d}",) for d in DISPLACEMENTS if d != default} | VARIANTS
    labels = [(b, b, ()) for b in BACKENDS]
    labels += [(f"{b} {name}", b, keys) for name, keys in models.items() for b in BACKENDS]
    return labels, list(models)


def cutting_window(t, x, y):
    """Samples in the middle half of the tool's motion along the path, and the motion's direction."""
    moving = np.hypot(np.gradient(x), np.gradient(y)) > 1e-9
    if moving.sum() < 4:
        return None, None
    t0, t1 = t[moving].min(), t[moving].max()
    mid = moving & (t > t0 + 0.25 * (t1 - t0)) & (t < t1 - 0.25 * (t1 - t0))
    direction = np.array([x[moving][-1] - x[moving][0], y[moving][-1] - y[moving][0]])
    return mid, direction / np.linalg.norm(direction)


def mean_force(t, xy, f):
    """Mean resistance against the motion and mean upward force while cutting."""
    mid, direction = cutting_window(t, xy[:, 0], xy[:, 1])
    if mid is None or not mid.any():
        return math.nan, math.nan
    return float(np.mean(-(f[mid, :2] @ direction))), float(np.mean(f[mid, 2]))


def model_forces(ctx, ref):
    """The haptic force model on the particles' own tool trajectory (seed 1's), replayed through
    `sandbench interactive` on every back-end: {back-end: the recorded session's arrays
    (exp_haptics.read_session)}; {} without xvfb-run, and in the tiny profile (the replays run in
    real time, and their forces follow the machine's timing)."""
    import shutil
    import exp_haptics
    if shutil.which("xvfb-run") is None or not ref.forces or ctx.profile_name == "tiny":
        return {}
    f = ref.forces[sorted(ref.forces)[0]]
    folder = ctx.runs / "particles" / f"{ref.case}-haptics"
    folder.mkdir(parents=True, exist_ok=True)
    trajectory = folder / "trajectory.csv"
    step = 0.001
    ts = np.arange(0.0, f[-1, 0], step)
    rows = ["t,x,y,z,buttons"] + [f"{t:.6f},{np.interp(t, f[:, 0], f[:, 1]):.9g},{np.interp(t, f[:, 0], f[:, 2]):.9g},"
                                  f"{np.interp(t, f[:, 0], f[:, 3]):.9g},0" for t in ts]
    trajectory.write_text("\n".join(rows) + "\n")
    what = ["particles haptics", trajectory, sbrun.ROOT / ref.scene, *BACKENDS]
    reuse = ctx.is_current(folder, what)
    out = {}
    for b in BACKENDS:
        _, out[b] = exp_haptics.replay(ctx.sandbench, b, folder, recording=trajectory, reuse=reuse,
                                       scene=sbrun.ROOT / ref.scene)
    ctx.mark_current(folder, what)
    return out


def tool_force_table(ctx, refs, sessions):
    """The tool's force while cutting: the particles' (mean ± sd over seeds) and the haptic force
    model's on the same trajectory (the model's force at the device's pose, as the session
    records it), per back-end."""
    rows = []
    for ref in refs:
        if not ref.forces:
            continue
        means = np.array([mean_force(f[:, 0], f[:, 1:3], f[:, 4:7]) for f in ref.forces.values()])
        model = {}
        for b, rec in sessions.get(ref.case, {}).items():
            force = rec["model"] if np.all(np.isfinite(rec["model"])) else rec["f"]
            model[b] = mean_force(rec["t"], rec["xy"], force)
        row = [ref.case, f"{means[:, 0].mean():.2f} ± {means[:, 0].std():.2f}",
               f"{means[:, 1].mean():.2f} ± {means[:, 1].std():.2f}"]
        for b in BACKENDS:
            row += [f"{model[b][0]:.2f}", f"{model[b][1]:.2f}"] if b in model else ["", ""]
        rows.append(row)
    if not rows:
        return ""
    headers = ["case", "particles: against the motion, N", "particles: up, N"]
    for b in BACKENDS:
        headers += [f"model on {b}: against the motion, N", f"model on {b}: up, N"]
    return ctx.table("particles_tool_force", headers, rows)


FLOOR_PARTS = 3  # the trench's floor is measured in this many stretches along the path


def stretches(values_mm):
    """'a / b / c' in tenths of a mm, without a negative zero."""
    return " / ".join(f"{v:.1f}" if round(v, 1) != 0 else "0.0" for v in values_mm)


def floor_along_table(ctx, cases):
    """Where the trench's floor lies below the tool, along the trench: per stroke case, the tool's
    width and depth and how far the axis lies below the tool's bottom (mm; negative: above it) in
    each stretch of the trench, with the tool still in at the path's end and after it lifted, for
    the grains' mean and the default model (grid; TIN lifted). Returns the Markdown and what the
    report says of it (floor_trends)."""
    rows, along = [], {}
    for c in (c for c in cases if c["sections"] is not None):
        stroke, depth = c["stroke"], c["tool_depth_m"]

        def below(surface):
            return [-(z + depth) * 1e3 for z in pm.floor_along(c["lattice"], surface, stroke, FLOOR_PARTS)]
        grains = {stage: below(c["ref"].mean(stage)) for stage in ("tool_in", "final")}
        model_tool_in = below(c["surfaces_tool_in"]["grid"])
        along[c["case"]] = {"width_mm": 2e3 * stroke.half_width, "depth_mm": depth * 1e3,
                            "tool_in_mm": grains["tool_in"], "model_tool_in_mm": model_tool_in}
        rows.append([c["case"], f"{2e3 * stroke.half_width:.0f} x {depth * 1e3:.0f}", stretches(grains["tool_in"]),
                     stretches(grains["final"]), stretches(model_tool_in),
                     stretches(below(c["surfaces"]["grid"])), stretches(below(c["surfaces"]["tin"]))])
    parts = " / ".join(("start", "middle", "end") if FLOOR_PARTS == 3 else [str(i + 1) for i in range(FLOOR_PARTS)])
    headers = ["case", "tool width x depth, mm", f"grains, tool in: below the tool, mm ({parts})", "grains, lifted",
               "grid, tool in", "grid, lifted", "TIN, lifted"]
    return (ctx.table("particles_floor", headers, rows) if rows else ""), floor_trends(along)


def floor_trends(along):
    """What the report says of the floor along the trench, with the tool still in: how far below the
    tool the grains lie where each cut starts (mm, min and max over the cases); the trenches whose
    floor rises above the tool's bottom by their end and those whose floor sinks further below it,
    with their depth-to-width ratios (a wall's slump reaches a trench's axis when it is deep for its
    width) and how far the sunk ones end below; the default model's (grid, tool in) least and most."""
    if not along:
        return {}
    start = [a["tool_in_mm"][0] for a in along.values()]
    ratio = {case: a["depth_mm"] / a["width_mm"] for case, a in along.items()}
    risen = [case for case, a in along.items() if a["tool_in_mm"][-1] < 0]
    sunk = [case for case, a in along.items() if a["tool_in_mm"][-1] > a["tool_in_mm"][0]]
    model = [v for a in along.values() for v in a["model_tool_in_mm"]]
    out = {"start_min_mm": min(start), "start_max_mm": max(start), "risen": risen, "sunk": sunk,
           "model_min_mm": round(min(model), 1) + 0.0, "model_max_mm": round(max(model), 1) + 0.0}  # no "-0.0"
    if risen:
        out["risen_ratio_min"] = min(ratio[c] for c in risen)
    if sunk:
        out["sunk_ratio_max"] = max(ratio[c] for c in sunk)
        out["sunk_end_min_mm"] = min(along[c]["tool_in_mm"][-1] for c in sunk)
        out["sunk_end_max_mm"] = max(along[c]["tool_in_mm"][-1] for c in sunk)
    # The depth-to-width ratio tells them apart when every risen trench is deeper for its width than every sunk one.
    out["by_ratio"] = bool(risen and sunk and out["risen_ratio_min"] > out["sunk_ratio_max"])
    return out


def run(ctx):
    refs = load_references()
    default = default_displacement(ctx)
    labels, others = variants(default)
    other = "rim" if "rim" in others else others[0]
    jobs = {}
    for ref in refs:
        scene_path = sbrun.ROOT / ref.scene
        for label, b, overrides in labels:
            if ref.case in POURS and overrides:  # a pour displaces nothing: its runs are the default's
                continue
            name = run_name(ref, label)
            jobs[name] = (scene_path, b, name, overrides)
            if "tool_in" in ref.surfaces:
                jobs[name + "-tool_in"] = (scene_path, b, name + "-tool_in", overrides + ("erosion.relax_at_end=false",))
    summaries = dict(zip(jobs, ctx.run_many("particles", list(jobs.values()))))
    names = [label for label, _, _ in labels]
    cases, rows_csv = [], []
    for ref in refs:
        scene = scene_of(ref)
        lattice = pm.Lattice(ref.origin, ref.spacing, ref.surfaces["final"].shape[1:])

        def surfaces(suffix=""):
            return {label: raster_of(ctx.runs / f"{run_name(ref, label)}{suffix}.h5", lattice) for label in names}
        final = surfaces()
        table, seeds, backends, base = case_rows(ref, scene, lattice, "final", final)
        case = {"case": ref.case, "scene": ref.scene, "mean": ref.mean("final"), "surfaces": final,
                "grain_mm": 1e3 * ref.material()["grains"]["diameter_m"],
                "x": ref.xs(), "y": ref.ys(), "backends": backends, "sections": None, "seeds": len(ref.seeds),
                "dem_cost_s": float(np.median(ref.cpu_seconds())), "dem_seeds": seeds,
                "critical": scene["material"]["critical_angle_deg"], "tool_depth_m": scene["tool"].get("depth_m"),
                "cost_s": {label: summaries[run_name(ref, label)]["time_s.total"] +
                           summaries[run_name(ref, label)].get("time_s.relax", 0.0) for label in names},
                "dilation": dilation(ref, scene, lattice), "lattice": lattice, "ref": ref,
                "stroke": None if ref.case in POURS else stroke_of(scene)}
        if base is not None:
            case["sections"] = {"u": seeds[0]["section_u_m"], "seeds": [s["section_z_m"] for s in seeds],
                                "backends": {label: backends[label]["section_z_m"] for label in names}}
            case["dem_self_rmse_m"] = float(np.mean([s["section_rmse_m"] for s in seeds]))
            case["between_backends_m"] = max(pm.rmse(backends[a]["section_z_m"], backends[b]["section_z_m"])
                                             for a in BACKENDS for b in BACKENDS if a < b)
        else:
            case["dem_self_rmse_m"] = float(np.mean([s["surface_rmse_m"] for s in seeds]))
        rows_csv += [[ref.case, "tool lifted"] + row for row in table]
        if base is not None:
            case["surfaces_tool_in"] = surfaces("-tool_in")
            tool_in, _, _, _ = case_rows(ref, scene, lattice, "tool_in", case["surfaces_tool_in"])
            rows_csv += [[ref.case, "tool in"] + row for row in tool_in]
        cases.append(case)
    if not cases:
        return {"cases": [], "table": "", "figures": {}, "displacement": default, "compared": other, "others": others,
                "variants": {}, "floor_table": "", "floor_along": {},
                "tool_force": "", "force_fit": {}, "bars": "", "bars_met": {}, "most_bars": None, "summary": {}}
    md = ctx.table("particles", ["case", "surface", "metric", "particles (mean ± sd over seeds)", *names], rows_csv)
    figures = {"sections": section_figure(ctx, cases, names), "difference": difference_figure(ctx, cases),
               "speed": speed_figure(ctx, cases, names)}
    out = values(cases, md, figures, other, others)
    sessions = {ref.case: model_forces(ctx, ref) for ref in refs if ref.forces}
    bars, met = bars_table(ctx, cases, names, default)
    out["floor_table"], out["floor_along"] = floor_along_table(ctx, cases)
    out.update({"displacement": default, "compared": other, "others": others, "bars": bars, "bars_met": met,
                "variants": {name: ", ".join(keys) for name, keys in VARIANTS.items()},
                "most_bars": max(met, key=lambda m: met[m][0]) if met else None,
                "tool_force": tool_force_table(ctx, refs, sessions),
                "force_fit": haptic_calibration.run(ctx, refs, sessions, {ref.case: force_parameters(ctx, scene_of(ref))
                                                                      for ref in refs})})
    return out


# What a real-time earthmoving model is held to against the particles after the tool lifted
# (Servin et al. 2021 report 10-25 % from DEM): header, metric keys, bar, and how the distance is
# taken ("abs": largest absolute difference over the keys, in `scale` units; "rel": relative;
# "value": the metric itself).
BARS = [("trench floor, mm (bar 2)", ("floor_m",), 2e-3, "abs", 1e3),
        ("berm / cut (bar 0.1)", ("berm_cut_ratio",), 0.1, "abs", 1.0),
        ("pile ahead (bar 25 %)", ("ahead_height_m",), 0.25, "rel", 100.0),
        ("side crests, mm (bar 1.5)", ("crest_left_m", "crest_right_m"), 1.5e-3, "abs", 1e3),
        ("section RMSE, mm (bar 2)", ("section_rmse_m",), 2e-3, "value", 1e3)]


def bars_table(ctx, cases, names, default):
    """Each stroke case and model: its distance from the grains' mean on each bar, and whether the
    bar holds; and how many bars each model meets over the cases and back-ends, [met, of]."""
    rows, met = [], {}
    for c in (c for c in cases if c["sections"] is not None):
        dem = {k: float(np.mean([s[k] for s in c["dem_seeds"]])) for _, keys, _, _, _ in BARS for k in keys}
        for label in names:
            m = c["backends"][label]
            row = [c["case"], label]
            for _, keys, bar, how, scale in BARS:
                if how == "value":
                    d = m[keys[0]]
                elif how == "rel":
                    d = abs(m[keys[0]] - dem[keys[0]]) / abs(dem[keys[0]])
                else:
                    d = max(abs(m[k] - dem[k]) for k in keys)
                row.append(f"{d * scale:.2g}{' %' if how == 'rel' else ''} {'yes' if d <= bar else 'no'}")
                count = met.setdefault(label.split()[1] if " " in label else default, [0, 0])
                count[0] += d <= bar
                count[1] += 1
            rows.append(row)
    return (ctx.table("particles_bars", ["case", "model"] + [b[0] for b in BARS], rows) if rows else ""), met


def values(cases, table, figures, other, others):
    """What the report's section says, from this run's numbers; `other` the displacement model the
    report sets beside the default, `others` every model the back-ends also ran with."""
    out_cases, summary = [], {}
    for c in cases:
        item = {"case": c["case"], "seeds": c["seeds"], "dem_cost_s": c["dem_cost_s"], "grain_mm": c["grain_mm"]}
        if c["sections"] is not None:
            rmse = {b: c["backends"][b]["section_rmse_m"] for b in BACKENDS}
            speedup = [c["dem_cost_s"] / max(c["cost_s"][b], 1e-9) for b in BACKENDS]
            shared = c["between_backends_m"] < 0.25 * min(rmse.values())
            item.update({"section_rmse_mm": {b: rmse[b] * 1e3 for b in BACKENDS},
                         "between_backends_mm": c["between_backends_m"] * 1e3,
                         "dem_self_mm": c["dem_self_rmse_m"] * 1e3,
                         "dilation_pct": 100 * c["dilation"][0], "dilation_sd_pct": 100 * c["dilation"][1],
                         "speedup_min": min(speedup), "speedup_max": max(speedup),
                         "other_rmse_mm": {b: c["backends"][f"{b} {other}"]["section_rmse_m"] * 1e3 for b in BACKENDS},
                         "others_rmse_mm": {o: {b: c["backends"][f"{b} {o}"]["section_rmse_m"] * 1e3 for b in BACKENDS}
                                            for o in others},
                         "verdict": ("the shared tool model: the back-ends agree far better with each other "
                                     "than with the grains" if shared else
                                     "partly the discretisation: back-ends differ by much of it")})
            for b in BACKENDS:  # the report's summary table joins the cases' cells
                summary.setdefault(b, {}).setdefault("accuracy vs particle sand", [])
                summary[b]["accuracy vs particle sand"].append(f"{c['case']} {rmse[b] * 1e3:.1f} mm")
        else:
            flank, flank_sd = spread([s["flank_deg"] for s in c["dem_seeds"]])
            item.update({"flank_deg": {b: c["backends"][b]["flank_deg"] for b in BACKENDS},
                         "surface_rmse_mm": {b: c["backends"][b]["surface_rmse_m"] * 1e3 for b in BACKENDS},
                         "dem_flank": flank, "dem_flank_sd": flank_sd, "critical": c["critical"],
                         "calibration": "within 1 degree" if abs(flank - c["critical"]) <= 1.0 else
                         "more than 1 degree off"})
        out_cases.append(item)
    summary = {b: {col: "section RMSE " + ", ".join(cells) for col, cells in cols.items()} for b, cols in summary.items()}
    verdicts = list(dict.fromkeys(c["verdict"] for c in out_cases if "verdict" in c))
    return {"cases": out_cases, "table": table, "figures": figures, "summary": summary, "verdicts": verdicts,
            "berms": berm_spread(cases)}


def berm_spread(cases):
    """The berms' section (mm^2, both sides, tool lifted) over the stroke cases: the grains' least and
    most, their cuts' and the berms' share of them, the default model's on the grid, and the case where the
    grid's falls furthest short of the grains' (its case, grid and grains mm^2)."""
    strokes = [c for c in cases if c["sections"] is not None]
    if not strokes:
        return {}
    grains = {c["case"]: np.mean([s["berm_area_m2"] for s in c["dem_seeds"]]) * 1e6 for c in strokes}
    share = [np.mean([s["berm_cut_ratio"] for s in c["dem_seeds"]]) for c in strokes]
    grid = {c["case"]: c["backends"]["grid"]["berm_area_m2"] * 1e6 for c in strokes}
    cut = [np.mean([s["cut_area_m2"] for s in c["dem_seeds"]]) * 1e6 for c in strokes]
    worst = min(grid, key=lambda k: grid[k] / grains[k])
    return {"grains_min": min(grains.values()), "grains_max": max(grains.values()), "cut_min": min(cut),
            "cut_max": max(cut), "share_min": min(share),
            "share_max": max(share), "grid_min": min(grid.values()), "grid_max": max(grid.values()),
            "worst": worst, "worst_grid": grid[worst], "worst_grains": grains[worst]}


if __name__ == "__main__":
    sbrun.main(run)
