#!/usr/bin/python3
"""experiments/particle_metrics.py on surfaces whose answers are known: a trench with a sloping
floor, in any direction of the stroke. The floor of stroke_metrics is the floor's mean over the
section band; floor_along gives it stretch by stretch from where the cut starts to the tool's back."""
import math
import sys
import unittest
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "experiments"))
import particle_metrics as pm  # noqa: E402

BED = 0.02
HALF_LENGTH, HALF_WIDTH = 0.01, 0.015


def trench(angle_deg, depth_at_start, depth_slope):
    """A 0.3 x 0.3 m raster at 1 mm with a trench along a 0.13 m stroke at angle_deg from x: its
    floor depth_at_start + depth_slope * s below the bed, its walls vertical, 10 mm wider each
    side than the tool (so the axis band sees the floor only); the stroke and the lattice."""
    lattice = pm.Lattice((0.0, 0.0), 0.001, (301, 301))
    a = math.radians(angle_deg)
    start = np.array([0.15, 0.15]) - 0.065 * np.array([math.cos(a), math.sin(a)])
    end = start + 0.13 * np.array([math.cos(a), math.sin(a)])
    stroke = pm.Stroke([start, end], HALF_LENGTH, HALF_WIDTH, BED)
    X, Y = lattice.node_xy()
    rel = np.stack([X - start[0], Y - start[1]], axis=-1)
    s, u = rel @ stroke.dir, rel @ stroke.normal
    inside = (s >= -0.02) & (s <= 0.15) & (np.abs(u) <= HALF_WIDTH + 0.01)
    surface = np.where(inside, BED - (depth_at_start + depth_slope * s), BED)
    return lattice, surface, stroke


class FloorAlong(unittest.TestCase):
    def test_flat_floor_is_the_same_in_every_stretch(self):
        for angle in (0.0, 30.0, 90.0, 217.0):
            lattice, surface, stroke = trench(angle, 0.012, 0.0)
            parts = pm.floor_along(lattice, surface, stroke, 3)
            self.assertEqual(len(parts), 3)
            for z in parts:
                self.assertAlmostEqual(z, -0.012, delta=1e-9, msg=f"angle {angle}")
            self.assertAlmostEqual(pm.stroke_metrics(lattice, surface, stroke)["floor_m"], -0.012, delta=1e-9)

    def test_sloping_floor_gives_each_stretch_its_mean(self):
        # Bilinear sampling is exact on a linear floor: each stretch's mean is the depth at its middle.
        slope = 0.05  # 5 mm deeper per 10 cm along the motion
        for angle in (0.0, 45.0, 123.0):
            lattice, surface, stroke = trench(angle, 0.010, slope)
            trench_end = stroke.length - stroke.half_length
            parts = pm.floor_along(lattice, surface, stroke, 4)
            for i, z in enumerate(parts):
                middle = (i + 0.5) * trench_end / 4
                self.assertAlmostEqual(z, -(0.010 + slope * middle), delta=1e-6, msg=f"angle {angle}, stretch {i}")
            self.assertLess(parts[-1], parts[0], "the floor deepens along the motion")

    def test_stretches_cover_the_trench_not_the_pile(self):
        # A pile on the tool's final footprint does not reach the last stretch.
        lattice, surface, stroke = trench(0.0, 0.012, 0.0)
        X, Y = lattice.node_xy()
        s = X - stroke.start[0]
        surface = np.where((s > stroke.length - stroke.half_length + 0.002) & (np.abs(Y - stroke.start[1]) < 0.02),
                           BED + 0.01, surface)
        self.assertAlmostEqual(pm.floor_along(lattice, surface, stroke, 3)[-1], -0.012, delta=1e-9)


if __name__ == "__main__":
    unittest.main()
