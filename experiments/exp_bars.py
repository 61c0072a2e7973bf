#!/usr/bin/python3
"""The pile's and the trench's bars on this machine: each back-end on the scene as shipped,
several runs each, the back-ends interleaved; per measure the medians of each back-end's runs, their
ratio TIN / grid against the bar, and the spread of the ratio over the rounds (the machine is shared,
so step times move between runs; RMSE and memory do not)."""
import statistics

import sbrun

# Runs per scene and back-end, interleaved (round r runs the TIN's r-th and the grid's r-th together).
REPEATS = 9

# scene -> [(measure, summary key, bar on the ratio TIN / grid)]
BARS = {
    "pile.toml": [("step time p50 (ms)", "step_ms.p50", 3.0),
                  ("RMSE against the cone (um)", "reference.rmse_m", 1.25),
                  ("memory at the end (bytes)", "memory_bytes", 1.0),
                  ("peak memory (bytes)", "memory_bytes_peak", 1.0),
                  ("settling time (s)", "time_s.relax", 10.0)],
    "trench.toml": [("step time p50 (ms)", "step_ms.p50", 5.0)],
}
SCALE = {"reference.rmse_m": 1e6}


def run(ctx):
    repeats = ctx.profile.get("bar_repeats", REPEATS)
    jobs = []
    for scene in BARS:
        jobs += [(sbrun.SCENES / scene, backend, f"bars/{scene.removesuffix('.toml')}-{backend}-{r}", [])
                 for r in range(repeats) for backend in ("tin", "grid")]
    summaries = ctx.run_many("bars", jobs)
    rows, missed, medians, ns_per_update, updates = [], [], {}, {}, {}
    for k, (scene, measures) in enumerate(BARS.items()):
        runs = summaries[2 * repeats * k:2 * repeats * (k + 1)]
        tin, grid = runs[0::2], runs[1::2]
        # The cost of one erosion update during the strokes (erosion time over updates, median of the runs).
        ns_per_update[scene] = {b: statistics.median(1e9 * r["time_s.erosion"] / max(r["erosion_updates"], 1) for r in rs)
                                for b, rs in (("tin", tin), ("grid", grid))}
        updates[scene] = (statistics.median(r["erosion_updates"] for r in tin) /
                          max(statistics.median(r["erosion_updates"] for r in grid), 1))
        for label, key, bar in measures:
            t = statistics.median(r[key] for r in tin)
            g = statistics.median(r[key] for r in grid)
            medians[scene, key] = {"tin": t, "grid": g}
            ratio = t / g
            per_round = sorted(a[key] / b[key] for a, b in zip(tin, grid))
            if ratio > bar:
                missed.append(f"{scene} {label.split(' (')[0]}")
            scale = SCALE.get(key, 1.0)
            rows.append([scene, label, t * scale, g * scale, f"{ratio:.2f}x", f"{per_round[0]:.2f}-{per_round[-1]:.2f}x",
                         f"{bar:g}x", "yes" if ratio <= bar else "no"])
    md = ctx.table("bars", ["scene", "measure", "tin median", "grid median", "tin / grid", "per round",
                            "bar", "within"], rows)
    return {"table": md, "repeats": repeats, "within": len(rows) - len(missed), "measures": len(rows), "missed": missed,
            "step_ratio": {sc: medians[sc, "step_ms.p50"]["tin"] / medians[sc, "step_ms.p50"]["grid"] for sc in BARS},
            "ns_per_update": ns_per_update, "update_ratio": updates,
            "summary": {b: {"step time": f"pile {medians['pile.toml', 'step_ms.p50'][b]:.3f} ms, "
                                         f"trench {medians['trench.toml', 'step_ms.p50'][b]:.3f} ms",
                            "settling time": f"pile {medians['pile.toml', 'time_s.relax'][b]:.3f} s"}
                        for b in ("tin", "grid")}}


if __name__ == "__main__":
    sbrun.main(run)
