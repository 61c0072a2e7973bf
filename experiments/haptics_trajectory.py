#!/usr/bin/python3
"""Smooth device trajectories for judging haptic rendering (replay files, README "Interactive mode and haptics").

One trajectory: the tool waits above the sand, plunges to its depth, holds, strokes along a heading, holds and
lifts. Every move follows a minimum-jerk profile, so position, velocity and acceleration are continuous and a
step in the force comes from the rendering, not from the motion. The plunge's peak speed is 1.875 times its mean
(15/8 for minimum jerk): 3 mm above to 10 mm deep in 0.122 s peaks at 0.2 m/s.

  haptics_trajectory.py OUT.csv [--surface-z 0.1] [--above-mm 3] [--depth-mm 10] [--plunge-s 0.122]
                        [--hold-s 0.4] [--heading-deg 45] [--stroke-m 0.1] [--stroke-s 1.5] [--rate-hz 1000]
                        [--centre X Y] [--wait-s 0.2]

The defaults are flat_stroke.toml's: sand 0.1 m high, the stroke centred on the domain's centre (--centre
0.5 0.5 for its sand on a 1 m square, `--set 'domain.size_m=[1.0,1.0]'`).
"""
import argparse
import math
import sys
from pathlib import Path

CENTRE = (0.35355339, 0.35355339)  # flat_stroke.toml's domain centre


def min_jerk(s):
    """Minimum-jerk blend from 0 to 1 for s in [0, 1]."""
    s = min(max(s, 0.0), 1.0)
    return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)


def trajectory(surface_z=0.1, above_mm=3.0, depth_mm=10.0, plunge_s=0.122, hold_s=0.4, heading_deg=45.0,
               stroke_m=0.1, stroke_s=1.5, rate_hz=1000.0, centre=CENTRE, wait_s=0.2):
    """Rows (t, x, y, z, buttons): wait (wait_s), plunge, hold, stroke, hold, lift, wait (0.2 s)."""
    h = math.radians(heading_deg)
    d = (math.cos(h), math.sin(h))
    x0 = (centre[0] - 0.5 * stroke_m * d[0], centre[1] - 0.5 * stroke_m * d[1])
    z_top, z_bottom = surface_z + 1e-3 * above_mm, surface_z - 1e-3 * depth_mm
    wait, lift_s = 0.2, plunge_s
    phases = [wait_s, plunge_s, hold_s, stroke_s, hold_s, lift_s, wait]
    ends = [sum(phases[:i + 1]) for i in range(len(phases))]
    rows = []
    n = int(round(ends[-1] * rate_hz))
    for i in range(n + 1):
        t = i / rate_hz
        plunge = min_jerk((t - ends[0]) / plunge_s)
        lift = min_jerk((t - ends[4]) / lift_s)
        stroke = min_jerk((t - ends[2]) / stroke_s)
        z = z_top + (z_bottom - z_top) * (plunge - lift)
        x = x0[0] + stroke_m * d[0] * stroke
        y = x0[1] + stroke_m * d[1] * stroke
        rows.append((t, x, y, z, 0))
    return rows


def write(path, rows):
    with open(path, "w") as f:
        f.write("t,x,y,z,buttons\n")
        for t, x, y, z, b in rows:
            f.write(f"{t:.6f},{x:.9f},{y:.9f},{z:.9f},{b}\n")


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("out")
    ap.add_argument("--surface-z", type=float, default=0.1, help="sand height, m")
    ap.add_argument("--above-mm", type=float, default=3.0, help="start this far above the sand")
    ap.add_argument("--depth-mm", type=float, default=10.0, help="tool bottom this far under the sand")
    ap.add_argument("--plunge-s", type=float, default=0.122, help="plunge duration (13 mm in 0.122 s peaks at 0.2 m/s)")
    ap.add_argument("--hold-s", type=float, default=0.4)
    ap.add_argument("--heading-deg", type=float, default=45.0)
    ap.add_argument("--stroke-m", type=float, default=0.1)
    ap.add_argument("--stroke-s", type=float, default=1.5)
    ap.add_argument("--rate-hz", type=float, default=1000.0)
    ap.add_argument("--centre", type=float, nargs=2, default=CENTRE, metavar=("X", "Y"),
                    help="the stroke's centre, m (default: flat_stroke.toml's domain centre)")
    ap.add_argument("--wait-s", type=float, default=0.2, help="time above the sand before the plunge")
    a = ap.parse_args(argv)
    for name in ("plunge_s", "hold_s", "stroke_s", "rate_hz", "wait_s"):
        if not getattr(a, name) > 0.0:
            print(f"--{name.replace('_', '-')} must be > 0 (got {getattr(a, name)})", file=sys.stderr)
            return 2
    if not all(math.isfinite(c) for c in a.centre):
        print(f"--centre must be finite (got {a.centre[0]} {a.centre[1]})", file=sys.stderr)
        return 2
    rows = trajectory(a.surface_z, a.above_mm, a.depth_mm, a.plunge_s, a.hold_s, a.heading_deg, a.stroke_m,
                      a.stroke_s, a.rate_hz, tuple(a.centre), a.wait_s)
    write(Path(a.out), rows)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
