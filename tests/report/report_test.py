#!/usr/bin/python3
"""experiments/report.py: templates fail loudly on a missing value, the summary table merges the
experiments' columns in order, the word counter counts prose only, and results/REPORT.md (once
written by report.py) stays within its word budget."""
import sys
import unittest
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "experiments"))
import jinja2  # noqa: E402
import report  # noqa: E402

# REPORT.md's prose: about 3,000 words, tables, figures and code blocks not counted.
WORD_BUDGET = 3300


class Render(unittest.TestCase):
    def test_missing_value_fails(self):
        with self.assertRaises(jinja2.UndefinedError):
            report.render("fig5_6", {"tin_vertices": 1})

    def test_every_experiment_has_a_template(self):
        import reproduce
        for key in reproduce.EXPERIMENTS:
            self.assertTrue((report.TEMPLATES / f"{key}.md.j2").exists(), key)

    def test_every_template_is_placed(self):
        placed = {k for _, _, keys in report.PARTS for k in keys}
        for t in report.TEMPLATES.glob("*.md.j2"):
            key = t.name.removesuffix(".md.j2")
            if key != "abstract":
                self.assertIn(key, placed, f"{t.name} has no place in report.PARTS")


class Verdicts(unittest.TestCase):
    def test_times(self):
        self.assertEqual(report.times(3.0, 1.5), "2.00x slower")
        self.assertEqual(report.times(1.0, 4.0), "4.00x faster")
        self.assertEqual(report.times(0.0, 1.0), "not comparable")

    def test_within(self):
        self.assertEqual(report.within(2.9, 3.0), "within")
        self.assertEqual(report.within(3.1, 3.0), "outside")


class Summary(unittest.TestCase):
    def test_columns_merge_in_order_and_empty_ones_are_left_out(self):
        values = {"a": {"summary": {"grid": {"stability": "18 ok"}, "tin": {"step time": "1 ms"}}},
                  "b": {"summary": {"tin": {"step time": "2 ms", "new column": "x"}}}, "c": {}}
        md = report.summary_table(values)
        lines = md.splitlines()
        self.assertEqual(lines[0], "| back-end | step time | stability | new column |")
        self.assertEqual(lines[2], "| tin | 1 ms; 2 ms |  | x |")
        self.assertEqual(lines[3], "| grid |  | 18 ok |  |")
        self.assertNotIn("particle", md)

    def test_no_summary_no_table(self):
        self.assertEqual(report.summary_table({"a": {}}), "")


class InteractiveScaling(unittest.TestCase):
    """exp_interactive_scaling's path from stats JSON to table, bars and section, on made-up stats (the replays
    themselves run in the smoke test's tiny profile)."""

    @staticmethod
    def stats(fps, step_p95, latency_p95, cells=40401, vertices=0, stamps=23):
        return {"fps": fps, "frame_ms.p50": 1e3 / fps, "frame_ms.p99": 2e3 / fps, "stamp_to_frame_ms.p50": 0.5 *
                latency_p95, "stamp_to_frame_ms.p95": latency_p95, "stamp_to_frame_ms.max": 1.2 * latency_p95,
                "stamp_to_take_ms.p95": 0.4 * latency_p95,
                "sim.step_ms.p50": 0.1, "sim.step_ms.p95": step_p95, "sim.step_cpu_ms.p95": 0.5 * step_p95,
                "sim.step_cpu_s.total": 20 * step_p95, "display_ms.p50": 0.05, "display_ms.p95": 0.1, "upload_ms.p95": 0.2, "sim.stamps": stamps, "sim.steps": 400, "cells": cells,
                "vertices": vertices}

    def test_cases_span_the_sizes_and_tiny_runs_one(self):
        import exp_interactive_scaling as x
        self.assertEqual(x.cases("tiny"), [("grid", 1.0, 0.01)])
        paper = x.cases("paper")
        self.assertIn(("grid",) + x.FINE, paper)
        self.assertIn(("sparse",) + x.COARSE, paper)
        self.assertIn(("grid",) + x.LARGE, paper)
        self.assertEqual([c for c in paper if c[0] == "tin"],
                         [("tin", 1.0, None), ("tin", 0.25, None), ("tin", 2.0, None), ("tin", 2.0475, None),
                          ("tin", 1.0, 0.0004), ("tin", 1.0, 0.0002), ("tin", 1.0, 0.0001)])
        self.assertIn(("grid", 0.25, 0.001), paper)
        self.assertEqual(x.overrides(("grid", 1.0, 0.001)), ["domain.size_m=[1.0, 1.0]", "grid.cell_m=0.001"])
        self.assertEqual(x.overrides(("tin", 1.0, 0.0002)), ["domain.size_m=[1.0, 1.0]", "terrain.kind=dunes",
                                                               "terrain.wavelength_m=0.1", "tin.tolerance_m=0.0002"])
        self.assertEqual(x.case_name(("tin", 1.0, 0.0002)), "tin-1m-dunes-0.2mm")

    def test_bars_table_and_section(self):
        import csv
        import tempfile
        import types
        import exp_interactive_scaling as x
        import sbrun
        made = {("grid", 1.0, 0.005): self.stats(20.0, 0.1, 40.0), ("grid", 1.0, 0.001): self.stats(20.0, 0.2, 60.0),
                ("grid", 2.0475, 0.0005): self.stats(14.0, 3.0, 90.0, cells=4096 ** 2),
                ("grid", 0.25, 0.001): self.stats(20.0, 0.18, 50.0, cells=251001),
                ("tin", 1.0, None): self.stats(50.0, 1.0, 30.0, cells=0, vertices=900, stamps=0),
                ("tin", 1.0, 0.0002): self.stats(45.0, 1.0, 40.0, cells=0, vertices=23000)}
        rows = {c: x.figures(c, s) for c, s in made.items()}
        rounds = {c: [r] for c, r in rows.items()}
        # Two more rounds of the 1 m bar cases: the step ratio 2.0, 1.4, 2.0 straddles its bar.
        for step in (0.14, 0.2):
            rounds[("grid", 1.0, 0.005)].append(x.figures(("grid", 1.0, 0.005), self.stats(20.0, 0.1, 40.0)))
            rounds[("grid", 1.0, 0.001)].append(x.figures(("grid", 1.0, 0.001), self.stats(20.0, step, 60.0)))
        self.assertEqual(rows[("tin", 1.0, None)]["elements"], 900)
        self.assertNotEqual(rows[("tin", 1.0, None)]["latency_p95"], rows[("tin", 1.0, None)]["latency_p95"],
                            "no stamp, no latency (NaN)")
        judged = x.judge(rounds)
        bars = {(b["bar"], b["backend"]): b["verdict"] for b in judged}
        self.assertEqual(bars[("fps 1 mm / 5 mm", "grid")], "met")  # 1.0 against 0.8, every round
        self.assertEqual(bars[("sim step p95 1 mm / 5 mm", "grid")], "straddled: met in 1 of 3 runs")
        self.assertEqual(judged[1]["measured"], "2 [1.4-2]")  # the rounds' median and range
        self.assertEqual(bars[("stamp to frame p95 at 1 mm", "grid")], "missed")  # 60 ms, every round
        self.assertEqual(bars[("fps at 4096 x 4096", "grid")], "missed (within 10%)")  # 14 against 15
        self.assertEqual(bars[("stamp to frame, largest, at 4096 x 4096", "grid")], "missed (within 10%)")  # 108
        self.assertEqual(len(bars), 5, "no sparse rows, no sparse bars")
        self.assertEqual(x.renderer_of(made.values()), "unknown")
        self.assertEqual(x.renderer_of([{"gl_renderer": "llvmpipe (LLVM 15.0.6, 256 bits)"}]),
                         "llvmpipe (LLVM 15.0.6, 256 bits)")
        with tempfile.TemporaryDirectory() as tmp:
            ctx = types.SimpleNamespace(results=Path(tmp), table=lambda *a: sbrun.Context.table(ctx, *a),
                                        figure=lambda fig, name: sbrun.Context.figure(ctx, fig, name))
            sbrun.env_ok()
            no_erosion = [x.figures(x.NO_EROSION[0], self.stats(25.0, 1.5, lat)) for lat in (38.0, 45.0, 41.0)]
            values = x.values(ctx, rounds, "llvmpipe", None, no_erosion)
            self.assertEqual((values["met"], values["straddled"]), (1, 1))
            self.assertEqual(values["latency"]["without"], {"median": 41.0, "lo": 38.0, "hi": 45.0})
            self.assertEqual(values["latency"]["take"]["median"], 24.0)  # 0.4 x 60 ms, every round
            with open(Path(tmp) / "interactive_scaling.csv") as f:
                table = list(csv.DictReader(f))
            self.assertEqual([(r["back-end"], r["terrain"]) for r in table],
                             [("grid", "flat")] * 4 + [("tin", "flat"), ("tin", "dunes")])
            self.assertEqual(float(table[1]["fps"]), 20.0)
            self.assertEqual(int(table[3]["elements"]), 4096 ** 2)
            self.assertTrue((Path(tmp) / values["png"]).stat().st_size > 0)
        text = report.render("interactive_scaling", values)
        self.assertIn("**Verdict.**", text)
        self.assertIn("**Method or code:**", text)
        self.assertIn("llvmpipe", text)
        self.assertIn("dunes\n45 fps at 23000 vertices", text)
        self.assertIn("CPU clock:\ngrid 2.00 (0.050 to 0.100 ms). The grid's at 1 mm on\n0.25, 1 m squares: "
                      "0.090, 0.100 ms (the domain's size does not enter).", text)
        grows = dict(values, same_cell={"grid": [(0.25, 0.09), (1.0, 0.2)]})
        self.assertIn("(it grows with the domain)", report.render("interactive_scaling", grows))
        self.assertIn("60 [60-60] in all, 41 [38-45] without erosion\n(`erosion.max_passes_per_step = 0`): erosion "
                      "shares two cores with the renderer (simulation\nCPU 4.00 s at 1 mm, 2.00 at 5 mm).", text)
        self.assertNotIn("erosion shares", report.render("interactive_scaling", dict(values, latency=dict(
            values["latency"], without={"median": 58.0, "lo": 52.0, "hi": 61.0}))),
            "no claim when the runs without erosion reach those with it")
        self.assertIn("Skipped: no display", report.render("interactive_scaling", {"skipped": "no display"}))


class Words(unittest.TestCase):
    def test_prose_only(self):
        text = ("# Title here\n\nTwo words.\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\n![fig](x.png)\n\n"
                "```\ncode is not counted\n```\nThe `sandbench --set` flag.\n")
        self.assertEqual(report.prose_words(text), 2 + 2 + 3)

    def test_committed_report_within_budget(self):
        path = ROOT / "results" / "REPORT.md"
        if not path.exists() or "## Abstract" not in path.read_text():
            self.skipTest("results/REPORT.md not yet written by report.py (make reproduce writes it)")
        words = report.prose_words(path.read_text())
        self.assertLessEqual(words, WORD_BUDGET, f"results/REPORT.md has {words} words of prose")


if __name__ == "__main__":
    unittest.main(verbosity=2)
