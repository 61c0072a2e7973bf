#!/usr/bin/python3
"""The sparse grid (OpenVDB) against the dense grid and the TIN on the shipped scenes: memory,
per-step time, settling time and volume drift, and whether the two grids hold the same heights.
Its verdict answers: does a sparse grid keep the paper's memory promise without the TIN's costs?"""
import sbrun

SCENES = ["flat_stroke", "pile", "trench", "dunes", "heightmap"]
BACKENDS = ["grid", "sparse", "tin"]


def final_raster(ctx, name):
    with sbrun.read_h5(ctx.runs / f"{name}.h5") as f:
        return f["/final/raster"][()]


def run(ctx):
    import numpy as np

    scenes = SCENES[:2] if ctx.profile_name == "tiny" else SCENES
    jobs = [(sbrun.SCENES / f"{sc}.toml", b, f"sparse/{sc}-{b}", []) for sc in scenes for b in BACKENDS]
    s = dict(zip([(sc, b) for sc in scenes for b in BACKENDS], ctx.run_many("sparse", jobs)))
    rows, same = [], {}
    for sc in scenes:
        g, sp, t = s[(sc, "grid")], s[(sc, "sparse")], s[(sc, "tin")]
        same[sc] = bool(np.array_equal(final_raster(ctx, f"sparse/{sc}-grid"), final_raster(ctx, f"sparse/{sc}-sparse")))
        rows.append([sc, g["memory_bytes"], sp["memory_bytes"], t["memory_bytes"], sp["memory_bytes"] / g["memory_bytes"],
                     sp["step_ms.p50"] / max(g["step_ms.p50"], 1e-30),
                     sp["time_s.relax"] / max(g["time_s.relax"], 1e-30) if g["time_s.relax"] > 0 else float("nan"),
                     sp["volume_drift_rel"], "yes" if same[sc] else "no"])
    md = ctx.table("sparse", ["scene", "grid bytes", "sparse bytes", "TIN bytes", "sparse / grid memory",
                              "sparse / grid step p50", "sparse / grid settling", "sparse drift (rel)",
                              "same heights as grid"], rows)
    local = [r for r in rows if r[0] in ("flat_stroke", "pile", "trench")]
    beats_tin = [r[0] for r in rows if r[2] < r[3]]
    worst_mem = max(local, key=lambda r: r[4])
    step = sorted(r[5] for r in rows)
    full = [r for r in rows if r[0] in ("dunes", "heightmap")]
    settle = [r[6] for r in rows if r[6] == r[6]] or [float("nan")]
    kept = worst_mem[4] <= 0.2
    drift = max(abs(r[7]) for r in rows)
    return {"table": md, "all_same": all(same.values()), "differ": [k for k, v in same.items() if not v],
            "local": [{"scene": r[0], "memory": r[4]} for r in local],
            "full": [{"scene": r[0], "memory": r[4]} for r in full],
            "beats_tin": beats_tin, "kept": kept, "worst_scene": worst_mem[0], "worst_memory": worst_mem[4],
            "step_min": step[0], "step_max": step[-1], "drift": drift, "verdict": "yes" if kept and step[-1] <= 2.0 else "partly",
            "summary": {"sparse": {"step time": f"{step[0]:.2f}-{step[-1]:.2f}x the grid's",
                                   "settling time": f"{min(settle):.2f}-{max(settle):.2f}x the grid's"}}}


if __name__ == "__main__":
    sbrun.main(run)
