"""Grains to surfaces: the upper envelope of the spheres on a raster, and what LAMMPS wrote."""
import numpy as np


class Raster:
    """A lattice of nodes over the domain, rows along y (the run files' convention)."""

    def __init__(self, origin, size, spacing):
        self.origin = (float(origin[0]), float(origin[1]))
        self.spacing = float(spacing)
        self.nx = int(round(size[0] / spacing)) + 1
        self.ny = int(round(size[1] / spacing)) + 1

    def xs(self):
        return self.origin[0] + self.spacing * np.arange(self.nx)

    def ys(self):
        return self.origin[1] + self.spacing * np.arange(self.ny)


def read_dump(path):
    """A LAMMPS `write_dump ... custom id x y z radius` file: an (n, 4) array of x, y, z, r,
    sorted by atom id so that dumps of one run compare grain by grain."""
    with open(path) as f:
        lines = f.read().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("ITEM: ATOMS")) + 1
    columns = lines[start - 1].split()[2:]
    data = np.loadtxt(lines[start:], ndmin=2)
    if data.size == 0:
        return np.zeros((0, 4))
    data = data[np.argsort(data[:, columns.index("id")])]
    return data[:, [columns.index(c) for c in ("x", "y", "z", "radius")]]


def envelope(grains, raster, floor):
    """The highest point of any sphere above each raster node; `floor` where none covers it."""
    heights = np.full(raster.ny * raster.nx, -np.inf)
    x, y, z, r = grains.T
    reach = int(np.ceil(r.max() / raster.spacing)) if len(r) else 0
    ci = np.rint((x - raster.origin[0]) / raster.spacing).astype(int)
    cj = np.rint((y - raster.origin[1]) / raster.spacing).astype(int)
    for dj in range(-reach, reach + 1):
        for di in range(-reach, reach + 1):
            i, j = ci + di, cj + dj
            inside = (i >= 0) & (i < raster.nx) & (j >= 0) & (j < raster.ny)
            dx = raster.origin[0] + i * raster.spacing - x
            dy = raster.origin[1] + j * raster.spacing - y
            cap2 = r * r - dx * dx - dy * dy
            hit = inside & (cap2 >= 0)
            np.maximum.at(heights, (j * raster.nx + i)[hit], z[hit] + np.sqrt(cap2[hit]))
    heights[~np.isfinite(heights)] = floor
    return np.maximum(heights, floor).reshape(raster.ny, raster.nx)


def grain_volume(grains):
    return float(np.sum(4.0 / 3.0 * np.pi * grains[:, 3] ** 3))


def read_force(path):
    """fix ave/time's file without its step column: t, x, y, z (the tool's bottom centre), fx, fy,
    fz (the sand's force on the tool), one row per output interval."""
    return np.loadtxt(path, comments="#", ndmin=2)[:, 1:]


def interior_mean(surface, raster, margin):
    """Mean of a surface over the nodes at least `margin` from the domain's border."""
    k = int(np.ceil(margin / raster.spacing))
    inner = surface[k:raster.ny - k, k:raster.nx - k]
    return float(inner.mean())
