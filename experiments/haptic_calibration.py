"""The haptic force model's parameters against another tool force on the same stroke (the
particles': experiments/exp_particles.py).

The model (common/haptics/force_model.hpp) is

    F = k d z^ - b c v - mu k d v_xy / max(|v_xy|, v_eps)

with d the penetration, c the contact fraction and v the velocity it was evaluated with, which a
session recorded by `sandbench interactive --record` holds for every servo tick. Given them the
force is linear in theta = (k, b, k mu): F = X theta, X's columns being d z^, -c v and
-d v_xy / max(|v_xy|, v_eps). A least-squares fit over the replayed series therefore needs no
run per parameter guess; d, c and v do not depend on the parameters (the replay device moves
the tool whatever force it feels, and the simulation stamps by pose).

Which parameters the data separate is measured, not assumed: a fit reports, per phase, the
correlation between the drag's and the friction's columns (at one speed with the tool fully in
sand both point against the motion with constant length, so they are nearly collinear) and the
condition number of the column-scaled design matrix.

The fitted values are a result (results/particles_haptic_fit.csv), not a scene's input: d
depends on the displacement model and the stamping, so they hold for the recording they came
from, and the DEM scenes keep the shipped values the replays are compared with.
"""
import math

import numpy as np

FRICTION_VELOCITY_EPS = 0.005  # m/s: force_model.hpp's kFrictionVelocityEps
PARAMETERS = ("k", "b", "kmu")  # theta: stiffness N/m, drag N s/m, stiffness times friction N/m
COLLINEAR = 0.98  # |correlation| of two columns above which the data cannot tell them apart


def regressors(depth, contact, velocity):
    """X: (samples, 3 components, 3 parameters), so that the model's force is X @ (k, b, k mu)."""
    depth, contact, velocity = np.asarray(depth, float), np.asarray(contact, float), np.asarray(velocity, float)
    X = np.zeros((len(depth), 3, 3))
    X[:, 2, 0] = depth
    X[:, :, 1] = -contact[:, None] * velocity
    speed = np.maximum(np.hypot(velocity[:, 0], velocity[:, 1]), FRICTION_VELOCITY_EPS)
    X[:, :2, 2] = -depth[:, None] * velocity[:, :2] / speed[:, None]
    return X


def theta(k, b, mu):
    return np.array([k, b, k * mu])


def predict(X, k, b, mu):
    """The model's force (samples, 3) with parameters k, b, mu."""
    return X @ theta(k, b, mu)


def fit(groups, fixed=None):
    """Least squares of the model to forces: groups is a list of (X, F) pairs, each weighted
    equally whatever its length (a short plunge counts as much as a long cut); fixed: {name: value}
    of parameters held (b, or kmu). A parameter whose column is zero in every group (the friction
    without horizontal motion) is not in the data: NaN. Returns {k, b, mu, separable, correlation,
    condition}: correlation the largest |correlation| between two fitted columns, condition the
    column-scaled design's condition number."""
    fixed = dict(fixed or {})
    rows, rhs = [], []
    for X, F in groups:
        w = 1.0 / math.sqrt(max(1, len(X)))
        rows.append(w * X.reshape(-1, 3))
        rhs.append(w * np.asarray(F, float).reshape(-1))
    A, y = np.vstack(rows), np.concatenate(rhs)
    values = dict.fromkeys(PARAMETERS, math.nan)
    for name, value in fixed.items():
        values[name] = value
        y = y - A[:, PARAMETERS.index(name)] * value
    scale = np.linalg.norm(A, axis=0)
    free = [i for i, name in enumerate(PARAMETERS) if name not in fixed and scale[i] > 1e-12 * max(scale.max(), 1e-300)]
    As = A[:, free] / scale[free]
    solution = np.linalg.lstsq(As, y, rcond=None)[0] / scale[free]
    for i, v in zip(free, solution):
        values[PARAMETERS[i]] = float(v)
    correlation = 0.0
    for a in range(len(free)):
        for c in range(a + 1, len(free)):
            correlation = max(correlation, abs(float(As[:, a] @ As[:, c])))  # columns of unit length
    condition = float(np.linalg.cond(As)) if len(free) else math.nan
    k, kmu = values["k"], values["kmu"]
    return {"k": k, "b": values["b"], "mu": kmu / k if k and not math.isnan(kmu) else math.nan,
            "correlation": correlation, "condition": condition, "separable": correlation < COLLINEAR}


def phases(t, xyz):
    """The tool's phases on its own trajectory (t, positions (n, 3)): `plunge` while it descends at
    its start before any horizontal motion, `cutting` while it moves along the path (at more than
    half its largest horizontal speed). Boolean arrays."""
    t, xyz = np.asarray(t, float), np.asarray(xyz, float)
    v = np.gradient(xyz, t, axis=0)
    horizontal = np.hypot(v[:, 0], v[:, 1])
    cutting = horizontal > 0.5 * horizontal.max()
    start = t[cutting].min() if cutting.any() else t[-1]
    plunge = (v[:, 2] < -0.5 * np.abs(v[:, 2]).max()) & (t < start)
    return {"plunge": plunge, "cutting": cutting}


def on_times(t_from, values, t_to):
    """Columns of `values` (n, m) sampled at t_from, interpolated linearly at t_to."""
    values = np.asarray(values, float).reshape(len(t_from), -1)
    return np.stack([np.interp(t_to, t_from, values[:, j]) for j in range(values.shape[1])], axis=1)


def phase_masks(reference_t, reference_xyz, t):
    """phases() of the reference trajectory, carried to the times t (nearest reference sample)."""
    ph = phases(reference_t, reference_xyz)
    index = np.clip(np.searchsorted(reference_t, t), 0, len(reference_t) - 1)
    before = np.clip(index - 1, 0, len(reference_t) - 1)
    nearest = np.where(np.abs(reference_t[before] - t) < np.abs(reference_t[index] - t), before, index)
    return {name: mask[nearest] for name, mask in ph.items()}


def summary(X, F, direction, k, b, mu):
    """The fitted and the reference force over one phase: means of the resistance against the
    motion `direction` (unit, horizontal) and of the upward force, and the RMS of the difference
    (horizontal and vertical parts)."""
    model = predict(X, k, b, mu)
    d = model - F
    return {"against_ref": float(np.mean(-(F[:, :2] @ direction))),
            "against_model": float(np.mean(-(model[:, :2] @ direction))),
            "up_ref": float(np.mean(F[:, 2])), "up_model": float(np.mean(model[:, 2])),
            "rms_xy": float(np.sqrt(np.mean(np.sum(d[:, :2] ** 2, axis=1)))),
            "rms_z": float(np.sqrt(np.mean(d[:, 2] ** 2)))}


def trend(distance, resistance):
    """Slope of the resistance along the path (N per m travelled), by least squares."""
    return float(np.polyfit(distance, resistance, 1)[0]) if len(distance) > 2 else math.nan


# The experiment: every case with a force series, its replayed sessions (exp_particles.model_forces).

def case_series(ref, sessions, bed_height_m):
    """Per phase, pooled over the back-ends' sessions: X (the regressors at each tick), F (the
    particles' force, mean over seeds, at the same time), seeds (each seed's, (seeds, n, 3)), and
    per tick the back-end and the distance travelled along the path; with the path's direction."""
    seeds = [ref.forces[k] for k in sorted(ref.forces)]
    t_ref, xyz_ref = seeds[0][:, 0], seeds[0][:, 1:4]
    cutting = phases(t_ref, xyz_ref)["cutting"]
    start = xyz_ref[cutting][0, :2]
    direction = xyz_ref[cutting][-1, :2] - start
    direction = direction / np.linalg.norm(direction)
    series = {"plunge": [], "cutting": []}
    for backend, rec in sessions.items():
        if not np.all(np.isfinite(rec["contact"])):
            raise RuntimeError(f"{ref.case} on {backend}: the session lacks the model's contact fraction and velocity "
                               "(recorded by an older sandbench)")
        t = rec["t"]
        forces = np.stack([on_times(s[:, 0], s[:, 4:7], t) for s in seeds])
        masks = phase_masks(t_ref, xyz_ref, t)
        in_sand = (rec["depth"] > 0) | (np.interp(t, t_ref, xyz_ref[:, 2]) < bed_height_m)
        masks["plunge"] &= in_sand
        X = regressors(rec["depth"], rec["contact"], rec["velocity"])
        for name, m in masks.items():
            series[name].append({"X": X[m], "F": forces.mean(axis=0)[m], "seeds": forces[:, m], "t": t[m],
                                 "backend": np.full(int(m.sum()), backend),
                                 "distance": (rec["xy"][m] - start) @ direction, "recorded": rec["model"][m]})
    pooled = {name: {key: np.concatenate([p[key] for p in parts], axis=-2 if key == "seeds" else 0)
                     for key in parts[0]} for name, parts in series.items() if parts}
    return pooled, direction


def row_of(label, data, direction, k, b, mu, correlation=None):
    """A table row: the parameters, the mean forces per phase (the particles' and the model's) and the RMS
    differences; the cutting columns empty when mu is not known (a plunge's fit)."""
    cells = [label, k, b, mu]
    plunge = summary(data["plunge"]["X"], data["plunge"]["F"], direction, k, b, 0.0 if math.isnan(mu) else mu)
    cells += [plunge["up_ref"], plunge["up_model"]]
    if math.isnan(mu):
        cells += [math.nan] * 4
    else:
        cut = summary(data["cutting"]["X"], data["cutting"]["F"], direction, k, b, mu)
        cells += [cut["against_ref"], cut["against_model"], cut["up_ref"], cut["up_model"]]
    cells += [rms(data["plunge"]["X"], data["plunge"]["F"], k, b, mu),
              math.nan if math.isnan(mu) else rms(data["cutting"]["X"], data["cutting"]["F"], k, b, mu),
              math.nan if correlation is None else correlation]
    return cells


def rms(X, F, k, b, mu):
    """RMS of |model - reference| over the samples, N."""
    d = predict(X, k, b, 0.0 if math.isnan(mu) else mu) - F
    return float(np.sqrt(np.mean(np.sum(d ** 2, axis=1))))


def scatter(data):
    """RMS of |seed - mean over seeds|: how far one particle run is from their mean, N."""
    d = data["seeds"] - data["F"][None]
    return float(np.sqrt(np.mean(np.sum(d ** 2, axis=2))))


HEADERS = ["case", "parameters", "k, N/m", "b, N s/m", "mu", "plunge: up, particles N", "plunge: up, model N",
           "cutting: against the motion, particles N", "cutting: against the motion, model N",
           "cutting: up, particles N", "cutting: up, model N", "plunge: RMS of model - particles, N",
           "cutting: RMS of model - particles, N", "drag-friction column correlation"]


def run(ctx, refs, sessions, parameters):
    """Fits (k, mu) with b held at the scenes' value over the cutting phase of every case with a force
    series (the calibration: the phase a depth-only model can follow), and per case and phase for
    comparison; writes the table particles_haptic_fit (.md, .csv) and the figure
    particles_haptic_force; returns what the report says. {} when no case has sessions (no
    xvfb-run, the tiny profile)."""
    import tomllib
    import sbrun
    cases = {}
    for ref in refs:
        if sessions.get(ref.case):
            scene = tomllib.loads((sbrun.ROOT / ref.scene).read_text())
            data, direction = case_series(ref, sessions[ref.case], scene["terrain"]["height_m"])
            if "plunge" in data and "cutting" in data:
                cases[ref.case] = (data, direction, ref)
    if not cases:
        return {}
    shipped = {case: parameters[case] for case in cases}
    b_held = next(iter(shipped.values()))[1]
    if any(p[1] != b_held for p in shipped.values()):
        raise RuntimeError(f"the cases' scenes differ in material.drag_n_s_per_m ({shipped}): no common b to hold")

    def groups(data, names):
        return [(data[n]["X"], data[n]["F"]) for n in names]
    calibrated = fit([g for data, _, _ in cases.values() for g in groups(data, ("cutting",))], {"b": b_held})
    rows, out = [], {"k": calibrated["k"], "b": b_held, "mu": calibrated["mu"], "cases": {}}
    for case, (data, direction, ref) in cases.items():
        k0, b0, mu0 = shipped[case]
        fits = {"cut, b held": fit(groups(data, ("cutting",)), {"b": b_held}),
                "plunge, b held": fit(groups(data, ("plunge",)), {"b": b_held}),
                "both phases, b held": fit(groups(data, ("plunge", "cutting")), {"b": b_held}),
                "cut, free": fit(groups(data, ("cutting",))),
                "both phases, free": fit(groups(data, ("plunge", "cutting")))}
        rows.append(row_of(case, data, direction, k0, b0, mu0))
        rows[-1][1:1] = ["shipped"]
        rows.append(row_of(case, data, direction, calibrated["k"], b_held, calibrated["mu"]))
        rows[-1][1:1] = ["calibrated (cut, every case, b held)"]
        for label, f in fits.items():
            row = row_of(case, data, direction, f["k"], f["b"], f["mu"], f["correlation"] if "free" in label else None)
            rows.append(row[:1] + [f"this case: {label}"] + row[1:])
        rows.append([case, "particles: one seed against their mean"] + [math.nan] * 9 +
                    [scatter(data["plunge"]), scatter(data["cutting"]), math.nan])
        # The pile ahead: how the resistance grows along the path, past its first quarter (the start's transient).
        cut = data["cutting"]
        later = cut["distance"] > cut["distance"].min() + 0.25 * np.ptp(cut["distance"])
        cal = predict(cut["X"], calibrated["k"], b_held, calibrated["mu"])
        default = predict(cut["X"], k0, b0, mu0)
        out["cases"][case] = {
            "shipped": {"k": k0, "b": b0, "mu": mu0},
            "plunge_k": fits["plunge, b held"]["k"], "cutting_k": fits["cut, b held"]["k"],
            "cutting_mu": fits["cut, b held"]["mu"],
            "free_b": fits["cut, free"]["b"], "free_mu": fits["cut, free"]["mu"],
            "free_cutting_correlation": fits["cut, free"]["correlation"],
            "separable_in_cutting": fits["cut, free"]["separable"],
            "plunge": summary(data["plunge"]["X"], data["plunge"]["F"], direction, calibrated["k"], b_held, 0.0),
            "cutting": summary(cut["X"], cut["F"], direction, calibrated["k"], b_held, calibrated["mu"]),
            "plunge_default": summary(data["plunge"]["X"], data["plunge"]["F"], direction, k0, b0, mu0),
            "cutting_default": summary(cut["X"], cut["F"], direction, k0, b0, mu0),
            "scatter_plunge": scatter(data["plunge"]), "scatter_cutting": scatter(cut),
            "trend_particles_n_per_dm": 0.1 * trend(cut["distance"][later], -(cut["F"][later][:, :2] @ direction)),
            "trend_model_n_per_dm": 0.1 * trend(cut["distance"][later], -(cal[later][:, :2] @ direction)),
            # The scene's parameters through the recorded d, c, v against the model's force the session
            # recorded (which adds the patch blend): the median is 0 when the regressors are the model.
            "recorded_check_n": float(np.median(np.linalg.norm(default - cut["recorded"], axis=1))),
        }
    md = ctx.table("particles_haptic_fit", HEADERS,
                   [["" if isinstance(v, float) and math.isnan(v) else v for v in row] for row in rows])
    out.update({"table": md, "figure": figure(ctx, cases, shipped, (calibrated["k"], b_held, calibrated["mu"]))})
    return out


def figure(ctx, cases, shipped, calibrated):
    """Per case: the force against the motion and upward over time, the particles' mean and range over
    seeds, the model with the scene's parameters and with the calibrated ones, on the first back-end's
    recorded d, c, v."""
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(cases), 2, figsize=(10, 3.0 * len(cases)), squeeze=False, sharex="row")
    for row, (case, (data, direction, ref)) in zip(axes, cases.items()):
        seeds = np.stack([ref.forces[k] for k in sorted(ref.forces)])
        t_ref = seeds[0, :, 0]
        parts = {"against the motion": lambda F: -(F[..., :2] @ direction), "up": lambda F: F[..., 2]}
        both = {n: data[n] for n in ("plunge", "cutting")}
        backend = both["cutting"]["backend"][0]
        for ax, (name, part) in zip(row, parts.items()):
            values = part(seeds[:, :, 4:7])
            ax.fill_between(t_ref, values.min(axis=0), values.max(axis=0), color="0.8",
                            label="particles (seeds' range)")
            ax.plot(t_ref, values.mean(axis=0), color="k", lw=1.2, label="particles (mean)")
            for label, params, colour in [("model, scene's parameters", shipped[case], "C3"),
                                          ("model, calibrated", calibrated, "C0")]:
                for phase, d in both.items():
                    m = d["backend"] == backend
                    ax.plot(d["t"][m], part(predict(d["X"][m], *params)), color=colour, lw=0.9,
                            label=f"{label} (on {backend})" if phase == "cutting" else None)
            ax.set_title(f"{case}: force {name}", fontsize=9)
            ax.set_xlabel("time, s")
            ax.set_ylabel("N (logarithmic above 1)")
            ax.set_yscale("symlog", linthresh=1.0)
        row[0].legend(fontsize=7)
    fig.tight_layout()
    return ctx.figure(fig, "particles_haptic_force")
