"""Shape metrics of a surface after a stroke or a pour, measured the same way on a particle
reference's surfaces and on a height-field run's raster, so the two compare.

Surfaces are (ny, nx) arrays of heights on a raster (origin, spacing; rows along y). Lengths in
m, areas in m^2, angles in degrees. A stroke's metrics use its first segment: `s` runs along the
motion from the path's start, `u` across it (positive to the left of the motion)."""
import math

import numpy as np


class Lattice:
    def __init__(self, origin, spacing, shape):
        self.origin = (float(origin[0]), float(origin[1]))
        self.spacing = float(spacing)
        self.ny, self.nx = shape

    def sample(self, surface, x, y):
        """Bilinear interpolation at points (x, y), clamped to the raster."""
        fx = np.clip((np.asarray(x) - self.origin[0]) / self.spacing, 0, self.nx - 1 - 1e-9)
        fy = np.clip((np.asarray(y) - self.origin[1]) / self.spacing, 0, self.ny - 1 - 1e-9)
        i, j = np.floor(fx).astype(int), np.floor(fy).astype(int)
        tx, ty = fx - i, fy - j
        return ((1 - tx) * (1 - ty) * surface[j, i] + tx * (1 - ty) * surface[j, i + 1] +
                (1 - tx) * ty * surface[j + 1, i] + tx * ty * surface[j + 1, i + 1])

    def node_xy(self):
        xs = self.origin[0] + self.spacing * np.arange(self.nx)
        ys = self.origin[1] + self.spacing * np.arange(self.ny)
        return np.meshgrid(xs, ys)


class Stroke:
    """A straight stroke: start, unit direction, length, the tool's half length along the motion
    and half width across it, and the bed's height."""

    def __init__(self, path, half_length, half_width, bed):
        a, b = np.asarray(path[0], float), np.asarray(path[1], float)
        self.start, self.length = a, float(np.linalg.norm(b - a))
        self.dir = (b - a) / self.length
        self.normal = np.array([-self.dir[1], self.dir[0]])
        self.half_length, self.half_width, self.bed = half_length, half_width, bed

    def point(self, s, u):
        return (self.start[0] + s * self.dir[0] + u * self.normal[0],
                self.start[1] + s * self.dir[1] + u * self.normal[1])


SECTION_BAND = (0.25, 0.70)  # the part of the path whose cross-sections are averaged
BORDER_M = 0.005  # sections stop this short of the domain's border, where grains cannot reach the wall


def section(lattice, surface, stroke, u, band=SECTION_BAND, samples=31):
    """The cross-section at offsets u, averaged along the band of the path."""
    ss = np.linspace(band[0] * stroke.length, band[1] * stroke.length, samples)
    S, U = np.meshgrid(ss, u)
    x, y = stroke.point(S, U)
    return lattice.sample(surface, x, y).mean(axis=1)


def _wall_angle(u, z, floor, bed):
    """The slope of one wall (u from the axis outwards) between 20 % and 80 % of its depth."""
    depth = bed - floor
    if depth <= 0:
        return math.nan
    sel = (z > floor + 0.2 * depth) & (z < floor + 0.8 * depth)
    first_rise = np.argmax(z >= bed - 0.2 * depth) if np.any(z >= bed - 0.2 * depth) else len(z)
    sel[first_rise:] = False
    if sel.sum() < 2:
        return math.nan
    slope = np.polyfit(u[sel], z[sel], 1)[0]
    return math.degrees(math.atan(abs(slope)))


def stroke_metrics(lattice, surface, stroke, initial=None):
    """Floor, berms, walls and areas of the averaged cross-section; the pile ahead of the tool at
    the path's end. Heights relative to the bed, in m."""
    spacing = lattice.spacing / 2
    reach = min(6 * stroke.half_width, 0.5 * _room_across(lattice, stroke) - BORDER_M)
    u = np.arange(-reach, reach + spacing / 2, spacing)
    z = section(lattice, surface, stroke, u) - stroke.bed
    axis = np.abs(u) <= 0.25 * stroke.half_width
    floor = float(z[axis].mean())
    out = {"floor_m": floor}
    for side, mask in (("left", u > 0), ("right", u < 0)):
        us, zs = np.abs(u[mask]), z[mask]
        order = np.argsort(us)
        us, zs = us[order], zs[order]
        k = int(np.argmax(zs))
        out[f"crest_{side}_m"] = float(zs[k])
        out[f"crest_{side}_from_edge_m"] = float(us[k] - stroke.half_width)
        out[f"wall_{side}_deg"] = _wall_angle(us, zs, floor, 0.0)
    cut = float(np.sum(np.clip(-z, 0, None)) * spacing)
    berm = float(np.sum(np.clip(z, 0, None)) * spacing)
    out.update({"cut_area_m2": cut, "berm_area_m2": berm, "berm_cut_ratio": berm / cut if cut > 0 else math.nan})
    out.update(_ahead(lattice, surface, stroke))
    out["section_u_m"], out["section_z_m"] = u, z
    return out


def floor_along(lattice, surface, stroke, parts=3):
    """The trench floor (the axis band's mean height relative to the bed, as stroke_metrics's
    floor) in `parts` equal stretches of the trench, from where the cut starts to the tool's
    back at the path's end."""
    u = np.arange(-0.25 * stroke.half_width, 0.25 * stroke.half_width + 1e-12, lattice.spacing / 2)
    trench = (stroke.length - stroke.half_length) / stroke.length
    edges = np.linspace(0.0, trench, parts + 1)
    return [float(section(lattice, surface, stroke, u, band=(a, b)).mean() - stroke.bed)
            for a, b in zip(edges[:-1], edges[1:])]


def _room_across(lattice, stroke):
    """Twice the distance from the path's middle to the domain's border across the motion."""
    mid = stroke.start + stroke.dir * stroke.length / 2
    x0, y0 = lattice.origin
    x1, y1 = x0 + lattice.spacing * (lattice.nx - 1), y0 + lattice.spacing * (lattice.ny - 1)
    room = []
    for n, lo, hi, c in ((stroke.normal[0], x0, x1, mid[0]), (stroke.normal[1], y0, y1, mid[1])):
        if abs(n) > 1e-12:
            room.append(min((hi - c) / abs(n), (c - lo) / abs(n)))
    return 2 * min(room)


def _ahead(lattice, surface, stroke):
    """Height and volume above the bed ahead of the tool's last position, within twice its width."""
    X, Y = lattice.node_xy()
    rel = np.stack([X - stroke.start[0], Y - stroke.start[1]], axis=-1)
    s, u = rel @ stroke.dir, rel @ stroke.normal
    ahead = (s >= stroke.length + stroke.half_length) & (np.abs(u) <= 2 * stroke.half_width)
    above = np.clip(surface - stroke.bed, 0, None)
    if not np.any(ahead):
        return {"ahead_height_m": math.nan, "ahead_volume_m3": math.nan}
    return {"ahead_height_m": float(above[ahead].max()),
            "ahead_volume_m3": float(above[ahead].sum() * lattice.spacing ** 2)}


def pile_metrics(lattice, surface, centre, bed):
    """A pile around `centre` on a bed at height `bed`: its height, the flank's slope fitted
    between 20 % and 80 % of the height over every node, the foot's mean radius, its volume."""
    X, Y = lattice.node_xy()
    r = np.hypot(X - centre[0], Y - centre[1])
    h = surface - bed
    near = r <= 3 * lattice.spacing
    height = float(h[near].max())
    sel = (h > 0.2 * height) & (h < 0.8 * height)
    slope = np.polyfit(r[sel], h[sel], 1)[0] if sel.sum() > 2 else math.nan
    foot = r[h > 0.05 * height]
    return {"height_m": height, "flank_deg": math.degrees(math.atan(-slope)),
            "radius_m": float(np.percentile(foot, 95)) if len(foot) else math.nan,
            "volume_m3": float(np.clip(h, 0, None).sum() * lattice.spacing ** 2)}


def rmse(a, b):
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2)))
