#!/usr/bin/python3
"""experiments/haptic_calibration.py: the least-squares fit of the haptic force model's (k, b, mu)
recovers known parameters from a synthetic series, says when the drag and the friction cannot
be told apart, and finds the plunge and the cut on a tool's trajectory."""
import math
import sys
import unittest
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "experiments"))
import haptic_calibration as hc  # noqa: E402

K, B, MU = 650.0, 3.0, 0.7


def stroke(speeds=(0.1,), dt=0.001):
    """A plunge 15 mm deep at 0.1 m/s, then a cut along x at each speed in turn: times,
    positions, and d, c, v as the model would see them (d the depth, c saturating over the
    first 3 mm, along the cut a depth that wanders as a surface would)."""
    t, xyz = [0.0], [np.array([0.0, 0.0, 0.005])]
    for _ in range(200):  # plunge 20 mm from 5 mm above the surface at z = 0
        t.append(t[-1] + dt)
        xyz.append(xyz[-1] + np.array([0.0, 0.0, -0.1 * dt]))
    for speed in speeds:
        for _ in range(int(0.05 / speed / dt)):
            t.append(t[-1] + dt)
            xyz.append(xyz[-1] + np.array([speed * dt, 0.0, 0.0]))
    t, xyz = np.array(t), np.array(xyz)
    v = np.gradient(xyz, t, axis=0)
    depth = np.maximum(0.0, -xyz[:, 2]) * (1.0 + 0.2 * np.sin(40.0 * xyz[:, 0]))
    contact = np.minimum(1.0, depth / 0.003)
    return t, xyz, depth, contact, v


def model_force(depth, contact, v, k=K, b=B, mu=MU):
    """The force model of common/haptics/force_model.hpp, written out."""
    speed = np.maximum(np.hypot(v[:, 0], v[:, 1]), hc.FRICTION_VELOCITY_EPS)
    f = np.zeros((len(depth), 3))
    f[:, 2] = k * depth
    f -= b * contact[:, None] * v
    f[:, :2] -= mu * k * depth[:, None] * v[:, :2] / speed[:, None]
    return f


class Fit(unittest.TestCase):
    def test_regressors_are_the_model(self):
        _, _, d, c, v = stroke()
        X = hc.regressors(d, c, v)
        np.testing.assert_allclose(hc.predict(X, K, B, MU), model_force(d, c, v), rtol=0, atol=1e-12)

    def test_recovers_known_parameters_with_two_speeds(self):
        _, _, d, c, v = stroke(speeds=(0.05, 0.2))
        X = hc.regressors(d, c, v)
        f = hc.fit([(X, model_force(d, c, v))])
        self.assertAlmostEqual(f["k"], K, delta=1e-6 * K)
        self.assertAlmostEqual(f["b"], B, delta=1e-6 * B)
        self.assertAlmostEqual(f["mu"], MU, delta=1e-6 * MU)
        self.assertTrue(f["separable"])

    def test_recovers_k_and_mu_with_b_held_under_noise(self):
        rng = np.random.default_rng(1)
        _, _, d, c, v = stroke()
        X = hc.regressors(d, c, v)
        noisy = model_force(d, c, v) + rng.normal(0.0, 0.05, size=(len(d), 3))
        f = hc.fit([(X, noisy)], {"b": B})
        self.assertEqual(f["b"], B)
        self.assertAlmostEqual(f["k"], K, delta=0.01 * K)
        self.assertAlmostEqual(f["mu"], MU, delta=0.01 * MU)

    def test_one_speed_in_full_contact_cannot_separate_drag_and_friction(self):
        t, xyz, d, c, v = stroke()
        cut = hc.phases(t, xyz)["cutting"]
        X = hc.regressors(np.full(cut.sum(), 0.015), np.ones(cut.sum()), v[cut])
        f = hc.fit([(X, hc.predict(X, K, B, MU))])
        self.assertGreater(f["correlation"], hc.COLLINEAR)
        self.assertFalse(f["separable"])
        # Held at its true value, b leaves k mu alone to fit, and it is found.
        held = hc.fit([(X, hc.predict(X, K, B, MU))], {"b": B})
        self.assertAlmostEqual(held["k"] * held["mu"], K * MU, delta=1e-6 * K * MU)

    def test_friction_without_horizontal_motion_is_not_in_the_data(self):
        t, xyz, d, c, v = stroke()
        plunge = hc.phases(t, xyz)["plunge"]
        X = hc.regressors(d[plunge], c[plunge], v[plunge])
        f = hc.fit([(X, model_force(d[plunge], c[plunge], v[plunge]))], {"b": B})
        self.assertAlmostEqual(f["k"], K, delta=1e-6 * K)
        self.assertTrue(math.isnan(f["mu"]))

    def test_groups_weigh_equally_whatever_their_length(self):
        # Two groups wanting k = 100 and k = 300 (no motion, d = 0.01): the fit is their middle
        # though one has ten times the samples.
        def group(n, k):
            X = hc.regressors(np.full(n, 0.01), np.ones(n), np.zeros((n, 3)))
            return X, hc.predict(X, k, 0.0, 0.0)
        f = hc.fit([group(100, 100.0), group(1000, 300.0)], {"b": 0.0, "kmu": 0.0})
        self.assertAlmostEqual(f["k"], 200.0, delta=1e-9)


class Phases(unittest.TestCase):
    def test_plunge_then_cut(self):
        t, xyz, *_ = stroke()
        ph = hc.phases(t, xyz)
        self.assertTrue(ph["plunge"][5:195].all())
        self.assertFalse(ph["plunge"][205:].any())
        self.assertTrue(ph["cutting"][205:-5].all())
        self.assertFalse(ph["cutting"][:195].any())
        # Carried to other times (a session's ticks), by the nearest sample.
        masks = hc.phase_masks(t, xyz, np.array([0.1, 0.4]))
        self.assertEqual(list(masks["plunge"]), [True, False])
        self.assertEqual(list(masks["cutting"]), [False, True])

    def test_trend(self):
        x = np.linspace(0.0, 0.1, 50)
        self.assertAlmostEqual(hc.trend(x, 1.0 + 4.0 * x), 4.0, delta=1e-9)


if __name__ == "__main__":
    unittest.main()
