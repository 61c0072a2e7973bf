"""The stored particle references: one HDF5 file per case (experiments/dem/references/CASE.h5).

Layout:
- root attributes: `case`, `scene` (the scene's path), `lammps_version`, `seeds`, `created`,
  `format` (1);
- `/raster`: attributes `origin_m`, `spacing_m` (rows along y, as the run files' rasters);
- `/surfaces/STAGE` for STAGE in `initial`, `tool_in` (the tool at the path's end, where the
  case has a tool), `final` (after the tool lifted and the sand settled): (seeds, ny, nx) heights
  in m, the upper envelope of the grains, stored to 10 um (HDF5's scale-offset filter);
- `/force/seedN`: (samples, 7): time s, the tool bottom's centre x, y, z m, and the sand's force
  on the tool fx, fy, fz N;
- `/provenance`: string datasets `material.toml`, `scene.toml`, `case.json` (its `material`
  table, where it has one, overrides the material file's keys: case_material.py), and
  `inputs/seedN/STAGE.in` (the LAMMPS inputs as run); attribute `runs` (JSON: per seed its
  stages' wall and CPU seconds, grain counts and grain volumes per stage, and the bed's offset).
Readers take the mean and spread over the seeds themselves."""
import json
import time
from pathlib import Path

import h5py
import numpy as np

FORMAT = 1
STAGES = ("initial", "tool_in", "final")


def _string(group, name, text):
    group.create_dataset(name, data=text, dtype=h5py.string_dtype())


def write(path, name, case, material_path, sides, folders):
    """Writes the reference of case NAME from its seeds' sidecars and result folders, whole or not
    at all (a temporary file renamed)."""
    import tomllib
    from run_dem import ROOT
    material = tomllib.loads(Path(material_path).read_text())
    scene = tomllib.loads((ROOT / case["scene"]).read_text())
    origin = scene.get("domain", {}).get("origin_m", [0.0, 0.0])
    results = [np.load(f / "result.npz") for f in folders]
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".h5.tmp")
    with h5py.File(tmp, "w") as f:
        f.attrs.update({"format": FORMAT, "case": name, "scene": case["scene"],
                        "lammps_version": sides[0]["lammps_version"], "seeds": [s["seed"] for s in sides],
                        "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())})
        raster = f.create_group("raster")
        raster.attrs["origin_m"] = np.asarray(origin, dtype=float)
        raster.attrs["spacing_m"] = float(material["reference"]["raster_m"])
        surfaces = f.create_group("surfaces")
        for stage in STAGES:
            if stage in results[0].files:
                data = np.stack([r[stage] for r in results]).astype(np.float64)
                surfaces.create_dataset(stage, data=data, compression="gzip", compression_opts=9, shuffle=True,
                                        scaleoffset=5)
        force = f.create_group("force")
        for side, r in zip(sides, results):
            if "force" in r.files:
                force.create_dataset(f"seed{side['seed']}", data=r["force"].astype(np.float32), compression="gzip")
        prov = f.create_group("provenance")
        _string(prov, "material.toml", Path(material_path).read_text())
        _string(prov, "scene.toml", (ROOT / case["scene"]).read_text())
        _string(prov, "case.json", json.dumps(case, sort_keys=True))
        for side in sides:
            for stage, text in side["inputs"].items():
                _string(prov, f"inputs/seed{side['seed']}/{stage}", text)
        prov.attrs["runs"] = json.dumps({f"seed{s['seed']}": {k: s[k] for k in
                                         ("stages", "grains", "grain_volume_m3", "bed_offset_m", "finished")}
                                         for s in sides})
    tmp.replace(path)
    return path


class Reference:
    """A stored reference, read whole: surfaces per stage (seeds, ny, nx), forces per seed."""

    def __init__(self, path):
        with h5py.File(path, "r") as f:
            if f.attrs.get("format") != FORMAT:
                raise ValueError(f"{path}: not a particle reference of format {FORMAT}")
            self.case = str(f.attrs["case"])
            self.scene = str(f.attrs["scene"])
            self.lammps_version = str(f.attrs["lammps_version"])
            self.seeds = [int(s) for s in f.attrs["seeds"]]
            self.origin = tuple(float(v) for v in f["raster"].attrs["origin_m"])
            self.spacing = float(f["raster"].attrs["spacing_m"])
            self.surfaces = {k: f["surfaces"][k][()] for k in f["surfaces"]}
            self.forces = {k: f["force"][k][()].astype(float) for k in f["force"]}
            self.runs = json.loads(f["provenance"].attrs["runs"])
            self.material_text = f["provenance"]["material.toml"][()].decode()
            self.case_spec = json.loads(f["provenance"]["case.json"][()].decode())

    def material(self):
        """The material the grains were run with: the material file and the case's own keys."""
        import tomllib
        from case_material import material_of
        return material_of(self.case_spec, tomllib.loads(self.material_text))

    def mean(self, stage):
        return self.surfaces[stage].mean(axis=0)

    def spread(self, stage):
        """Standard deviation over the seeds, per node."""
        return self.surfaces[stage].std(axis=0)

    def xs(self):
        return self.origin[0] + self.spacing * np.arange(self.surfaces["final"].shape[2])

    def ys(self):
        return self.origin[1] + self.spacing * np.arange(self.surfaces["final"].shape[1])

    def cpu_seconds(self):
        """LAMMPS's CPU seconds per seed, summed over its stages."""
        return [sum(st["cpu_s"] for st in run["stages"].values()) for run in self.runs.values()]
