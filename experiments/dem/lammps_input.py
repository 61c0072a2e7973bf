"""LAMMPS inputs for the particle references, generated from a scene (the height fields' own
TOML: domain, bed, tool, path, depth) and the DEM material (material.toml).

Two stages per case and seed, each a plain LAMMPS input:
- `bed`: grains dropped from a loose lattice into the domain, settled, cut flat at the scene's
  bed height and settled again; a restart file and a dump of the settled bed.
- `tool`: from that restart, the tool plunges at the path's first point, follows the path at the
  case's speed, lifts out and is removed, and the sand settles; dumps with the tool in and after
  it left, and the tool's force and position over time.
A pour case (`tool.shape = "pour"`) is one stage, `pour`: grains fall from above the pour point
onto a frozen rough layer of grains at the bed's surface.

Every length is SI. The sand occupies the domain between frictional side walls; below
`bed_margin_grains` grains under the tool's bottom it is a frozen layer of grains (sand the tool
never reaches need not be simulated)."""
import math

SAND, FLOOR = 1, 2  # atom types


class SceneError(ValueError):
    """A scene the particle reference cannot model; the message names the key."""


def _get(d, dotted, default=None):
    node = d
    for part in dotted.split("."):
        if not isinstance(node, dict) or part not in node:
            return default
        node = node[part]
    return node


def _fmt(x):
    return f"{x:.9g}"


class Geometry:
    """What the DEM needs of a scene, checked: domain, bed, tool and path."""

    def __init__(self, scene, material):
        self.origin = [float(v) for v in _get(scene, "domain.origin_m", [0.0, 0.0])]
        self.size = [float(v) for v in _get(scene, "domain.size_m")]
        kind = _get(scene, "terrain.kind", "flat")
        if kind != "flat":
            raise SceneError(f"terrain.kind = {kind!r}: the particle reference models a flat bed only")
        self.bed_height = float(_get(scene, "terrain.height_m", 0.1))
        self.shape = _get(scene, "tool.shape", "disk")
        if self.shape not in ("disk", "box", "pour"):
            raise SceneError(f"tool.shape = {self.shape!r}: the particle reference models disk, box and pour")
        if _get(scene, "tool.profile", "flat") != "flat":
            raise SceneError("tool.profile: the particle reference models a flat-bottomed tool only")
        self.radius = float(_get(scene, "tool.radius_m", 0.02))
        self.box = [float(v) for v in _get(scene, "tool.size_m", [0.04, 0.02])]
        self.depth = float(_get(scene, "tool.depth_m", 0.01))
        self.path = [[float(v) for v in p] for p in _get(scene, "stroke.path_m")]
        self.z_path = _get(scene, "stroke.z_m")
        self.repeat = int(_get(scene, "stroke.repeat", 1))
        self.pour_volume = float(_get(scene, "tool.volume_m3", 0.0)) * self.repeat
        d = material["grains"]["diameter_m"]
        margin = material["numerics"]["bed_margin_grains"] * d
        if self.shape == "pour":
            self.floor_z = self.bed_height  # the pour lands on a frozen layer at the bed's surface
        else:
            if self.repeat != 1:
                raise SceneError("stroke.repeat: the particle reference follows the path once")
            if self.shape == "box" and any(
                    abs(b[0] - a[0]) > 1e-12 and abs(b[1] - a[1]) > 1e-12 for a, b in zip(self.path, self.path[1:])):
                raise SceneError("stroke.path_m: a box tool follows axis-parallel segments only in the particle reference")
            lowest = min(self.bottoms())
            self.floor_z = max(0.0, lowest - margin)
            if lowest <= self.floor_z:
                raise SceneError(f"tool.depth_m = {self.depth}: the tool reaches the bed's bottom (z = 0)")
        if self.bed_height - self.floor_z < 0 or self.size[0] < 8 * d or self.size[1] < 8 * d:
            raise SceneError("domain.size_m: at least 8 grains a side")

    def bottoms(self):
        """The tool bottom's z at each waypoint."""
        if self.z_path is not None:
            return [float(z) for z in self.z_path]
        return [self.bed_height - self.depth] * len(self.path)

    def footprint_half(self, direction):
        """Half extents of the tool's footprint along x and y while it moves along `direction`."""
        if self.shape == "disk":
            return self.radius, self.radius
        along, across = self.box[0] / 2, self.box[1] / 2
        return (along, across) if abs(direction[0]) >= abs(direction[1]) else (across, along)


def _header(geo, material, z_top):
    g, n = material["grains"], material["numerics"]
    d_max = g["diameter_m"] * (1 + g["diameter_spread"])
    x0, y0 = geo.origin
    x1, y1 = x0 + geo.size[0], y0 + geo.size[1]
    return "\n".join([
        "units si",
        "atom_style sphere",
        "boundary f f f",
        "newton off",
        "comm_modify vel yes",
        f"region domain block {_fmt(x0)} {_fmt(x1)} {_fmt(y0)} {_fmt(y1)} {_fmt(geo.floor_z - d_max)} {_fmt(z_top)} units box",
        "create_box 2 domain",
        f"timestep {_fmt(n['time_step_s'])}",
        "neighbor " + _fmt(0.2 * g["diameter_m"]) + " bin",
        "neigh_modify delay 0 every 1 check yes",
    ])


def _contact(material):
    """The granular contact model's arguments (pair_coeff and the walls share them)."""
    c = material["contact"]
    return (f"hertz/material {_fmt(c['youngs_modulus_pa'])} {_fmt(c['restitution'])} {_fmt(c['poisson_ratio'])} "
            f"tangential mindlin NULL 1.0 {_fmt(c['sliding_friction'])} "
            f"rolling sds {_fmt(c['rolling_stiffness_n_per_m'])} {_fmt(c['rolling_damping_n_s_per_m'])} "
            f"{_fmt(c['rolling_friction'])} twisting marshall damping tsuji")


def _wall_contact(material):
    c = material["contact"]
    return "granular " + _contact(material).replace(
        f"mindlin NULL 1.0 {_fmt(c['sliding_friction'])}", f"mindlin NULL 1.0 {_fmt(c['wall_friction'])}")


def _physics(geo, material):
    """Pair style, gravity, integration of the sand, the domain's walls and the frozen floor."""
    d = material["grains"]["diameter_m"]
    x0, y0 = geo.origin
    x1, y1 = x0 + geo.size[0], y0 + geo.size[1]
    return "\n".join([
        "pair_style granular",
        f"pair_coeff * * {_contact(material)}",
        "group sand type 1",
        "group floor type 2",
        "fix gravity sand gravity 9.81 vector 0 0 -1",
        "fix integrate sand nve/sphere",
        f"fix side_x sand wall/gran {_wall_contact(material)} xplane {_fmt(x0)} {_fmt(x1)}",
        f"fix side_y sand wall/gran {_wall_contact(material)} yplane {_fmt(y0)} {_fmt(y1)}",
        f"fix bottom sand wall/gran {_wall_contact(material)} zplane {_fmt(geo.floor_z - d / 2)} NULL",
    ])


def _floor(geo, material):
    """A frozen layer of touching grains (the mean diameter) whose tops lie at floor_z."""
    g = material["grains"]
    d = g["diameter_m"]
    x0, y0 = geo.origin
    x1, y1 = x0 + geo.size[0], y0 + geo.size[1]
    zc = geo.floor_z - d / 2
    return "\n".join([
        f"region floor_layer block {_fmt(x0)} {_fmt(x1)} {_fmt(y0)} {_fmt(y1)} {_fmt(zc - d / 4)} {_fmt(zc + d / 4)} units box",
        f"lattice sc {_fmt(d)} origin 0.5 0.5 0.5",
        f"create_atoms {FLOOR} region floor_layer units box",
        f"set type {FLOOR} diameter {_fmt(d)}",
        f"set type {FLOOR} density {_fmt(g['density_kg_per_m3'])}",
    ])


def lattice_fill_height(geo, material):
    """Height of the loose lattice that settles into at least the bed plus two grains."""
    g = material["grains"]
    d, s = g["diameter_m"], g["diameter_spread"]
    spacing = d * (1 + s) * 1.2
    mean_volume = math.pi / 6 * d ** 3 * (1 + s * s)  # E[d^3] of a uniform spread, to first order
    lattice_fraction = mean_volume / spacing ** 3
    settled_fraction = 0.6
    thickness = geo.bed_height - geo.floor_z + 2 * d
    return spacing, geo.floor_z + thickness * settled_fraction / lattice_fraction


def _random_diameters(group, material, seed):
    g = material["grains"]
    d, s = g["diameter_m"], g["diameter_spread"]
    return "\n".join([
        f"variable grain_d atom {_fmt(d)}*(1+{_fmt(s)}*(2*random(0,1,{seed})-1))",
        f"set group {group} diameter v_grain_d",
        f"set group {group} density {_fmt(g['density_kg_per_m3'])}",
    ])


def bed_input(geo, material, seed, restart="bed.restart", dump="bed.dump"):
    """Stage `bed`: the settled flat bed at the scene's height."""
    g, n = material["grains"], material["numerics"]
    d = g["diameter_m"]
    spacing, fill = lattice_fill_height(geo, material)
    jitter = 0.45 * (spacing - d * (1 + g["diameter_spread"]))
    x0, y0 = geo.origin
    x1, y1 = x0 + geo.size[0], y0 + geo.size[1]
    gap = spacing / 2
    settle_steps = int(round(n["settle_s"] / n["time_step_s"]))
    return "\n".join([
        f"# sandbench particle reference: the bed (seed {seed})",
        _header(geo, material, fill + 2 * d),
        _floor(geo, material),
        f"region fill block {_fmt(x0 + gap)} {_fmt(x1 - gap)} {_fmt(y0 + gap)} {_fmt(y1 - gap)} "
        f"{_fmt(geo.floor_z + gap)} {_fmt(fill)} units box",
        f"lattice sc {_fmt(spacing)} origin 0.5 0.5 0.5",
        f"create_atoms {SAND} region fill units box",
        "group sand type 1",
        _random_diameters("sand", material, seed),
        # The lattice is regular: a random offset within its gaps breaks the columns' symmetry.
        f"displace_atoms sand random {_fmt(jitter)} {_fmt(jitter)} 0 {seed} units box",
        _physics(geo, material),
        "thermo 2000",
        "thermo_style custom step time atoms ke",
        f"run {settle_steps}",
        # Cut flat: grains whose centre lies a fifth of a grain above the bed go (the envelope of
        # what stays then lies near the bed's height); the tool's depth counts from the level the
        # settled bed has (measured from its dump).
        f"region above block INF INF INF INF {_fmt(geo.bed_height + 0.2 * d)} INF units box",
        "delete_atoms region above",
        f"run {settle_steps // 2}",
        f"write_dump sand custom {dump} id x y z radius",
        f"write_restart {restart}",
    ]) + "\n"


def tool_schedule(geo, material, speed, bed_level):
    """The tool's waypoints in time: (t, x, y, z_bottom), plunge, path, lift. `bed_level` is the
    settled bed's measured surface, which the tool's depth counts from."""
    n = material["numerics"]
    offset = bed_level - geo.bed_height
    bottoms = [z + offset for z in geo.bottoms()]
    top = bed_level + n["clearance_m"]
    plunge = n["plunge_speed_m_per_s"]
    (x, y), t = geo.path[0], 0.0
    points = [(t, x, y, top)]
    t += (top - bottoms[0]) / plunge
    points.append((t, x, y, bottoms[0]))
    for (px, py), z in zip(geo.path[1:], bottoms[1:]):
        lx, ly, lz = points[-1][1:]
        t += math.dist((lx, ly, lz), (px, py, z)) / speed
        points.append((t, px, py, z))
    tool_in = t
    lx, ly, lz = points[-1][1:]
    t += (top - lz) / plunge
    points.append((t, lx, ly, top))
    return points, tool_in


def _piecewise(points, axis):
    """An equal-style LAMMPS expression of one coordinate (axis 1, 2, 3) of a piecewise-linear
    trajectory, as a displacement from its first point; `v_tool_t` is the tool's clock."""
    base = points[0][axis]
    terms = []
    for a, b in zip(points, points[1:]):
        ta, tb, va, vb = a[0], b[0], a[axis] - base, b[axis] - base
        if tb <= ta or (va == 0 and vb == 0):
            continue
        slope = (vb - va) / (tb - ta)
        terms.append(f"(v_tool_t>={_fmt(ta)})*(v_tool_t<{_fmt(tb)})*({_fmt(va)}+{_fmt(slope)}*(v_tool_t-{_fmt(ta)}))")
    last = points[-1][axis] - base
    if last != 0:
        terms.append(f"(v_tool_t>={_fmt(points[-1][0])})*{_fmt(last)}")
    return "+".join(terms) if terms else "0"


def _tool_region(geo, points, height):
    x, y, z = points[0][1:]
    move = "move v_tool_dx v_tool_dy v_tool_dz side out units box"
    if geo.shape == "disk":
        return f"region tool cylinder z {_fmt(x)} {_fmt(y)} {_fmt(geo.radius)} {_fmt(z)} {_fmt(z + height)} {move}"
    direction = (points[2][1] - points[1][1], points[2][2] - points[1][2]) if len(points) > 2 else (1.0, 0.0)
    hx, hy = geo.footprint_half(direction)
    return (f"region tool block {_fmt(x - hx)} {_fmt(x + hx)} {_fmt(y - hy)} {_fmt(y + hy)} "
            f"{_fmt(z)} {_fmt(z + height)} {move}")


def tool_input(geo, material, speed, bed_level, restart="bed.restart", tool_in_dump="tool_in.dump",
               final_dump="final.dump", force_file="force.txt"):
    """Stage `tool`: the stroke from the settled bed, and the settling after the tool lifted."""
    n = material["numerics"]
    dt = n["time_step_s"]
    points, tool_in = tool_schedule(geo, material, speed, bed_level)
    height = geo.depth + 0.1  # tall enough to stand above any pile it pushes
    every = max(1, int(round(n["output_interval_s"] / dt)))
    return "\n".join([
        "# sandbench particle reference: the tool's stroke",
        f"read_restart {restart}",
        f"timestep {_fmt(dt)}",
        "neighbor " + _fmt(0.2 * material["grains"]["diameter_m"]) + " bin",
        "neigh_modify delay 0 every 1 check yes",
        f"pair_coeff * * {_contact(material)}",
        _physics(geo, material),
        "reset_timestep 0",
        f"variable tool_t equal step*{_fmt(dt)}",
        f"variable tool_dx equal {_piecewise(points, 1)}",
        f"variable tool_dy equal {_piecewise(points, 2)}",
        f"variable tool_dz equal {_piecewise(points, 3)}",
        _tool_region(geo, points, height),
        f"fix tool sand wall/gran/region {_wall_contact(material)} region tool contacts",
        # The sand's force on the tool: minus the sum of the tool's contact forces on the grains.
        "compute tool_on_sand sand reduce sum f_tool[2] f_tool[3] f_tool[4]",
        "variable fx equal -c_tool_on_sand[1]",
        "variable fy equal -c_tool_on_sand[2]",
        "variable fz equal -c_tool_on_sand[3]",
        f"variable x equal {_fmt(points[0][1])}+v_tool_dx",
        f"variable y equal {_fmt(points[0][2])}+v_tool_dy",
        f"variable z equal {_fmt(points[0][3])}+v_tool_dz",
        f"fix force_out all ave/time {every} 1 {every} v_tool_t v_x v_y v_z v_fx v_fy v_fz file {force_file}",
        "thermo 2000",
        "thermo_style custom step time atoms ke v_fx v_fy v_fz",
        f"run {int(math.ceil(tool_in / dt))}",
        f"write_dump sand custom {tool_in_dump} id x y z radius",
        f"run {int(math.ceil((points[-1][0] - tool_in) / dt))}",
        # The tool leaves: lifted, it still stood in the pile it pushed (it is taller than any
        # pile), so it is removed before the sand settles, as a lifted blade is.
        "unfix force_out",
        "uncompute tool_on_sand",
        "unfix tool",
        "thermo_style custom step time atoms ke",
        f"run {int(math.ceil(n['settle_s'] / dt))}",
        f"write_dump sand custom {final_dump} id x y z radius",
    ]) + "\n"


def pour_input(geo, material, seed, pour_s, dump="final.dump"):
    """Stage `pour`: the scene's volume poured at its point onto a frozen layer of grains."""
    g, n = material["grains"], material["numerics"]
    d, s = g["diameter_m"], g["diameter_spread"]
    dt = n["time_step_s"]
    packing = 0.6  # the bulk volume's fraction of grains
    mean_volume = math.pi / 6 * d ** 3 * (1 + s * s)
    count = int(round(geo.pour_volume * packing / mean_volume))
    cone_height = (3 * geo.pour_volume * math.tan(math.radians(40)) ** 2 / math.pi) ** (1 / 3)
    x, y = geo.path[0]
    r = max(geo.radius, 2.4 * d)  # wide enough to insert the grains at a few thousand a second
    z_lo = geo.floor_z + cone_height + 2 * d
    z_hi = z_lo + 0.06
    steps = int(round((pour_s + n["settle_s"]) / dt))
    return "\n".join([
        f"# sandbench particle reference: a pile poured at one point (seed {seed}, {count} grains)",
        _header(geo, material, z_hi + d),
        _floor(geo, material),
        "group sand type 1",
        _physics(geo, material),
        f"region pour_region cylinder z {_fmt(x)} {_fmt(y)} {_fmt(r)} {_fmt(z_lo)} {_fmt(z_hi)} units box",
        f"fix pour sand pour {count} {SAND} {seed} region pour_region "
        f"diam range {_fmt(d * (1 - s))} {_fmt(d * (1 + s))} dens {_fmt(g['density_kg_per_m3'])} "
        f"{_fmt(g['density_kg_per_m3'])} vol 0.3 200 vel 0 0 0 0 -0.5",
        "thermo 2000",
        "thermo_style custom step time atoms ke",
        f"run {steps}",
        f"write_dump sand custom {dump} id x y z radius",
    ]) + "\n"
