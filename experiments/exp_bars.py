#!/usr/bin/python3
"""The pile's and the trench's bars (issue 11) on this machine: each back-end on the scene as shipped,
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
    rows, missed = [], []
    for k, (scene, measures) in enumerate(BARS.items()):
        runs = summaries[2 * repeats * k:2 * repeats * (k + 1)]
        tin, grid = runs[0::2], runs[1::2]
        for label, key, bar in measures:
            t = statistics.median(r[key] for r in tin)
            g = statistics.median(r[key] for r in grid)
            ratio = t / g
            per_round = sorted(a[key] / b[key] for a, b in zip(tin, grid))
            if ratio > bar:
                missed.append(f"{scene} {label.split(' (')[0]}")
            scale = SCALE.get(key, 1.0)
            rows.append([scene, label, t * scale, g * scale, f"{ratio:.2f}x", f"{per_round[0]:.2f}-{per_round[-1]:.2f}x",
                         f"{bar:g}x", "yes" if ratio <= bar else "no"])
    md = ctx.table("bars", ["scene", "measure", "tin median", "grid median", "tin / grid", "per round",
                            "bar", "within"], rows)
    return f"""## The pile's and the trench's bars on this machine

{md}
- Each back-end on the scene as shipped, {repeats} runs each, interleaved; the ratio of the medians against the bar
  (issue 11). Within: {len(rows) - len(missed)} of {len(rows)}; missed: {', '.join(missed) or 'none'}. Step times
  are the per-step p50 of one run; they move with the machine's other load (the per-round column) and
  with its vector lanes (the header: the grid's kernel runs its visits in them, the TIN's visits are
  scalar), so a ratio near its bar can fall either side of it between reproductions.
"""


if __name__ == "__main__":
    sbrun.main(run)
