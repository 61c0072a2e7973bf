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
