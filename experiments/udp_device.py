#!/usr/bin/env python3
"""Plays a haptic device over sandbench's UDP bridge (README: "Interactive mode and haptics").

It sends pose packets to 127.0.0.1:PORT at a fixed rate, as a real device's driver would,
receives the force packet sandbench answers each servo tick with, and reports what it got.
The motion is a replay file (CSV t,x,y,z,buttons) or a stroke built from a scene: hover above
the first waypoint, press into the sand to the tool depth, follow the path, lift.

Wire format (little-endian, 48 bytes each way):
  pose  = <I I d d d d I I : magic 0x31504253 "SBP1", seq, t_s, x, y, z, buttons, 0
  force = <I I d d d d I f : magic 0x31464253 "SBF1", seq answered, servo t_s, fx, fy, fz,
                              flags (1 contact, 2 clamped, 4 stale), force limit in N

Examples:
  sandbench interactive experiments/scenes/flat_stroke.toml --backend grid --device udp:47000 &
  python3 experiments/udp_device.py --port 47000 --scene experiments/scenes/flat_stroke.toml --out forces.json
  python3 experiments/udp_device.py --scene experiments/scenes/flat_stroke.toml --write-csv stroke.csv
"""
import argparse
import csv
import json
import math
import select
import socket
import struct
import sys
import time
import tomllib

POSE = struct.Struct("<IIddddII")
FORCE = struct.Struct("<IIddddIf")
POSE_MAGIC = 0x31504253
FORCE_MAGIC = 0x31464253
FLAG_CONTACT, FLAG_CLAMPED, FLAG_STALE = 1, 2, 4


def lerp(a, b, u):
    return tuple(x + u * (y - x) for x, y in zip(a, b))


def scene_stroke(path, duration_s, hover_m, extra_depth_m):
    """Keyframes (t, x, y, z) for a scene's stroke: descend, follow the path, lift."""
    with open(path, "rb") as f:
        scene = tomllib.load(f)
    terrain = scene.get("terrain", {})
    if terrain.get("kind", "flat") != "flat":
        print(f"udp_device: {path}: terrain is not flat; using terrain.height_m as the surface",
              file=sys.stderr)
    surface = float(terrain.get("height_m", 0.1))
    depth = float(scene.get("tool", {}).get("depth_m", 0.01)) + extra_depth_m
    waypoints = [tuple(map(float, p)) for p in scene["stroke"]["path_m"]]
    if "z_m" in scene["stroke"]:
        print("udp_device: stroke.z_m ignored; the tool goes to surface - tool.depth_m", file=sys.stderr)
    top, bottom = surface + hover_m, surface - depth
    lengths = [math.dist(a, b) for a, b in zip(waypoints, waypoints[1:])]
    total = sum(lengths) or 1.0
    t_down, t_path = 0.15 * duration_s, 0.7 * duration_s
    x0, y0 = waypoints[0]
    keys = [(0.0, x0, y0, top), (t_down, x0, y0, bottom)]
    t = t_down
    for (a, b), length in zip(zip(waypoints, waypoints[1:]), lengths):
        t += t_path * length / total
        keys.append((t, b[0], b[1], bottom))
    xe, ye = waypoints[-1]
    keys.append((duration_s, xe, ye, top))
    return keys


def csv_keys(path):
    keys = []
    with open(path, newline="") as f:
        rows = (r for r in csv.reader(f) if r and not r[0].startswith("#"))
        header = [h.strip() for h in next(rows)]
        if header != ["t", "x", "y", "z", "buttons"]:
            sys.exit(f"udp_device: {path}: the first table must have the header t,x,y,z,buttons")
        for r in rows:
            try:
                keys.append(tuple(float(v) for v in r[:4]) + (int(r[4]),))
            except (ValueError, IndexError):
                break  # the next table of a session file
    t0 = keys[0][0]
    return [(t - t0, x, y, z, b) for t, x, y, z, b in keys]


def pose_at(keys, t):
    """Linear interpolation of (t, x, y, z[, buttons]) keyframes; held after the end."""
    if t <= keys[0][0]:
        k = keys[0]
        return k[1:4], (k[4] if len(k) > 4 else 0)
    for a, b in zip(keys, keys[1:]):
        if t <= b[0]:
            u = (t - a[0]) / (b[0] - a[0]) if b[0] > a[0] else 1.0
            return lerp(a[1:4], b[1:4], u), (a[4] if len(a) > 4 else 0)
    k = keys[-1]
    return k[1:4], (k[4] if len(k) > 4 else 0)


def write_csv(keys, path, rate_hz):
    end = keys[-1][0]
    n = int(end * rate_hz) + 1
    with open(path, "w") as f:
        f.write("t,x,y,z,buttons\n")
        for i in range(n):
            t = min(end, i / rate_hz)
            (x, y, z), b = pose_at(keys, t)
            f.write(f"{t:.6f},{x:.9f},{y:.9f},{z:.9f},{b}\n")


def wait_for_answer(sock, target, keys, deadline_s):
    """Sends the first pose every 10 ms until sandbench answers with a force packet (it is up
    and listening), so nothing depends on how long its start takes; exits after deadline_s."""
    (x, y, z), buttons = pose_at(keys, 0.0)
    start = time.monotonic()
    while time.monotonic() - start < deadline_s:
        sock.sendto(POSE.pack(POSE_MAGIC, 0, 0.0, x, y, z, buttons, 0), target)
        if select.select([sock], [], [], 0.01)[0]:
            try:
                if len(sock.recv(64)) == FORCE.size:
                    return
            except ConnectionRefusedError:
                time.sleep(0.01)  # nobody listens yet
    sys.exit(f"udp_device: no answer from 127.0.0.1:{target[1]} within {deadline_s} s")


def play(keys, port, rate_hz, duration_s, settle_s, answer_deadline_s=0.0):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sock.setblocking(False)
    target = ("127.0.0.1", port)
    if answer_deadline_s > 0:
        wait_for_answer(sock, target, keys, answer_deadline_s)
    stats = {"poses_sent": 0, "forces_received": 0, "packets_rejected": 0, "all_finite": True,
             "force_max_n": 0.0, "force_limit_n": None, "within_limit": True,
             "ticks_in_contact": 0, "ticks_clamped": 0, "ticks_stale": 0}
    period = 1.0 / rate_hz
    start = time.monotonic()
    seq = 0
    end = duration_s + settle_s
    while True:
        now = time.monotonic() - start
        if now >= end:
            break
        if now < duration_s:
            (x, y, z), buttons = pose_at(keys, now)
            sock.sendto(POSE.pack(POSE_MAGIC, seq & 0xffffffff, now, x, y, z, buttons, 0), target)
            stats["poses_sent"] += 1
            seq += 1
        while True:
            try:
                data = sock.recv(64)
            except (BlockingIOError, ConnectionRefusedError):
                break
            if len(data) != FORCE.size:
                stats["packets_rejected"] += 1
                continue
            magic, _, _, fx, fy, fz, flags, limit = FORCE.unpack(data)
            if magic != FORCE_MAGIC:
                stats["packets_rejected"] += 1
                continue
            stats["forces_received"] += 1
            finite = all(math.isfinite(v) for v in (fx, fy, fz))
            stats["all_finite"] &= finite
            norm = math.sqrt(fx * fx + fy * fy + fz * fz) if finite else float("inf")
            stats["force_max_n"] = max(stats["force_max_n"], norm)
            stats["force_limit_n"] = float(limit)
            stats["within_limit"] &= norm <= float(limit) * (1 + 1e-6)
            stats["ticks_in_contact"] += bool(flags & FLAG_CONTACT)
            stats["ticks_clamped"] += bool(flags & FLAG_CLAMPED)
            stats["ticks_stale"] += bool(flags & FLAG_STALE)
        next_t = start + (int(now / period) + 1) * period
        select.select([sock], [], [], max(0.0, next_t - time.monotonic()))
    if stats["force_max_n"] == float("inf"):
        stats["force_max_n"] = None
    return stats


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    src = ap.add_mutually_exclusive_group(required=True)
    src.add_argument("--scene", help="build the stroke from this scene's [stroke] and [tool]")
    src.add_argument("--replay", help="play this replay file (CSV t,x,y,z,buttons)")
    ap.add_argument("--port", type=int, help="sandbench's UDP port (--device udp:PORT)")
    ap.add_argument("--rate-hz", type=float, default=1000.0, help="poses per second (default 1000)")
    ap.add_argument("--duration", type=float, default=4.0, help="seconds of motion (scene stroke)")
    ap.add_argument("--settle", type=float, default=0.3, help="seconds to keep listening afterwards")
    ap.add_argument("--wait", type=float, default=0.0, help="seconds to wait before the first pose")
    ap.add_argument("--wait-for-answer", type=float, default=0.0, metavar="DEADLINE_S",
                    help="before the motion, repeat the first pose until sandbench answers (give up after DEADLINE_S)")
    ap.add_argument("--hover", type=float, default=0.01, help="start and end this far above the sand, m")
    ap.add_argument("--extra-depth", type=float, default=0.0, help="press this much deeper than tool.depth_m, m")
    ap.add_argument("--write-csv", help="write the motion as a replay file and exit")
    ap.add_argument("--out", help="write what was received as JSON here (default: stdout)")
    args = ap.parse_args()

    keys = (scene_stroke(args.scene, args.duration, args.hover, args.extra_depth) if args.scene
            else csv_keys(args.replay))
    if args.write_csv:
        write_csv(keys, args.write_csv, 200.0)
        return 0
    if args.port is None or not 1 <= args.port <= 65535:
        ap.error("--port in [1, 65535] is required unless --write-csv is given")
    time.sleep(args.wait)
    duration = keys[-1][0]
    stats = play(keys, args.port, args.rate_hz, duration, args.settle, args.wait_for_answer)
    text = json.dumps(stats, indent=2)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text + "\n")
    else:
        print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
