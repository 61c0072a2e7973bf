#!/usr/bin/python3
"""The particle reference pipeline end to end on a tiny case (tests/dem/tiny_cases.toml: a few
hundred grains, seconds of LAMMPS): inputs generated from a scene, `lmp` run, surfaces and the
tool's force reduced and written to a reference file, which is read back and checked:
- every surface and force sample finite, the surfaces within the domain's plausible heights;
- the grains conserved (the same count and grain volume before, with the tool in, and after);
- the tool met the sand: it was pushed back against its motion while it cut, and the final
  surface has a cut below the bed along the path;
- a second start finds the run done and runs nothing;
- the tool is removed after it lifts and before the sand settles (a lifted tool left in place
  holds the back face of the pile it pushed);
- a scene it cannot model is refused up front (exit 2, naming the key);
- a case's own material keys (another grain size) reach the run, its key and the reader; a key the
  material file lacks is refused up front.
Usage: dem_tiny_test.py (LAMMPS's `lmp` on PATH; the test is skipped, exit 77, without it)."""
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent.parent
sys.path.insert(0, str(ROOT / "experiments" / "dem"))
import reference_file  # noqa: E402

RUN_DEM = [sys.executable, str(ROOT / "experiments" / "dem" / "run_dem.py"),
           "--cases-file", str(ROOT / "tests" / "dem" / "tiny_cases.toml"), "--seeds", "1"]


def check(cond, message):
    if not cond:
        sys.exit(f"FAIL: {message}")
    print(f"ok: {message}")


def refuses_what_it_cannot_model(tmp):
    """A scene the particles cannot model (dunes) is refused before any run: exit 2, the key named,
    nothing written."""
    cases = Path(tmp) / "bad_cases.toml"
    cases.write_text('[bad]\nscene = "experiments/scenes/dunes.toml"\nspeed_m_per_s = 0.1\n')
    proc = subprocess.run(RUN_DEM[:2] + ["--cases-file", str(cases), "--work", f"{tmp}/bad-work", "--out",
                                         f"{tmp}/bad-ref"], capture_output=True, text=True, timeout=120)
    check(proc.returncode == 2 and "terrain.kind" in proc.stderr and not Path(tmp, "bad-ref").exists(),
          f"an unsupported scene is refused naming terrain.kind ({proc.stderr.strip()})")


def a_case_changes_its_grains(tmp):
    """`material = {...}` in a case overrides the material file's keys for that case only: the
    LAMMPS inputs and the run's key follow it; a misspelt key is refused before any run."""
    import tomllib
    import lammps_input
    import run_dem
    from case_material import material_of
    with open(ROOT / "experiments" / "dem" / "material.toml", "rb") as f:
        material = tomllib.load(f)
    coarse = material_of({"material": {"grains": {"diameter_m": 0.003}}}, material)
    check(coarse["grains"]["diameter_m"] == 0.003 and coarse["grains"]["diameter_spread"] ==
          material["grains"]["diameter_spread"] and material["grains"]["diameter_m"] == 0.0025,
          "a case's grain size overrides that key only, and leaves the material file's alone")
    with open(ROOT / "tests" / "dem" / "tiny_scene.toml", "rb") as f:
        scene = tomllib.load(f)
    text = lammps_input.bed_input(lammps_input.Geometry(scene, coarse), coarse, 1)
    check("0.003" in text and "0.0025" not in text, "the bed's LAMMPS input uses the case's grains")
    cases = Path(tmp) / "grain_cases.toml"
    cases.write_text('[a]\nscene = "tests/dem/tiny_scene.toml"\nspeed_m_per_s = 0.2\n'
                     '[b]\nscene = "tests/dem/tiny_scene.toml"\nspeed_m_per_s = 0.2\n'
                     'material = { grains = { diameter_m = 0.003 } }\n')
    specs = run_dem.specs_for(cases, ["a", "b"], [1], Path(tmp), ROOT / "experiments" / "dem" / "material.toml",
                              "lmp", 1)
    check(specs[0]["key"] != specs[1]["key"], "the run's key changes with the case's grains")
    cases.write_text('[bad]\nscene = "tests/dem/tiny_scene.toml"\nspeed_m_per_s = 0.2\n'
                     'material = { grains = { diameter = 0.003 } }\n')
    proc = subprocess.run(RUN_DEM[:2] + ["--cases-file", str(cases), "--work", f"{tmp}/grain-work", "--out",
                                         f"{tmp}/grain-ref"], capture_output=True, text=True, timeout=120)
    check(proc.returncode == 2 and "material.grains.diameter" in proc.stderr and not Path(tmp, "grain-ref").exists(),
          f"a material key the file lacks is refused naming it ({proc.stderr.strip()})")


def tool_leaves_before_the_sand_settles():
    """The generated stroke lifts the tool, removes it, then settles: the final surface is sand
    that stands on its own."""
    import tomllib
    import lammps_input
    with open(ROOT / "tests" / "dem" / "tiny_scene.toml", "rb") as f:
        scene = tomllib.load(f)
    with open(ROOT / "experiments" / "dem" / "material.toml", "rb") as f:
        material = tomllib.load(f)
    geo = lammps_input.Geometry(scene, material)
    lines = lammps_input.tool_input(geo, material, 0.2, geo.bed_height).splitlines()
    runs = [i for i, line in enumerate(lines) if line.startswith("run ")]
    unfix = lines.index("unfix tool") if "unfix tool" in lines else -1
    final = next(i for i, line in enumerate(lines) if "final.dump" in line)
    check(len(runs) == 3 and runs[1] < unfix < runs[2] < final,
          "the tool is lifted, then removed, then the sand settles, then the final surface is dumped")


def main():
    tool_leaves_before_the_sand_settles()
    with tempfile.TemporaryDirectory() as tmp:
        refuses_what_it_cannot_model(tmp)
        a_case_changes_its_grains(tmp)
    if shutil.which("lmp") is None:
        print("lmp not found: skipped (Debian: lammps, installed by .ci/deps.sh)")
        return 77
    with tempfile.TemporaryDirectory() as tmp:
        args = RUN_DEM + ["--work", f"{tmp}/work", "--out", f"{tmp}/ref"]
        proc = subprocess.run(args, capture_output=True, text=True, timeout=600)
        check(proc.returncode == 0, f"run_dem.py exits 0 ({proc.stderr[-1500:]})")
        ref = reference_file.Reference(Path(tmp) / "ref" / "tiny.h5")
        check(ref.lammps_version.startswith("LAMMPS ("), f"provenance names LAMMPS's version: {ref.lammps_version}")
        check(set(ref.surfaces) == {"initial", "tool_in", "final"}, "three surfaces stored")
        for stage, s in ref.surfaces.items():
            check(np.all(np.isfinite(s)) and s.min() >= -1e-9 and s.max() < 0.05, f"{stage} surface finite, 0..5 cm")
        force = ref.forces["seed1"]
        check(force.shape[1] == 7 and np.all(np.isfinite(force)), f"force finite, {len(force)} samples")
        run = ref.runs["seed1"]
        counts, volumes = run["grains"], run["grain_volume_m3"]
        check(counts["initial"] > 100 and len(set(counts.values())) == 1, f"grains conserved: {counts}")
        check(max(volumes.values()) - min(volumes.values()) <= 1e-12 * max(volumes.values()),
              f"grain volume conserved: {volumes}")
        moving = (force[:, 1] > 0.013) & (force[:, 1] < 0.027) & (np.abs(np.gradient(force[:, 1])) > 0)
        check(moving.sum() > 3 and np.mean(force[moving, 4]) < 0,
              f"the sand pushes back against the motion while the tool cuts "
              f"(mean fx {np.mean(force[moving, 4]):.3f} N over {moving.sum()} samples)")
        final = ref.mean("final")
        axis = final[15, 14:27]  # y = 15 mm, x = 14..26 mm: the path behind the tool
        check(axis.mean() < 0.008 - 0.001, f"a cut along the path: {1e3 * axis.mean():.2f} mm (bed 8 mm)")
        again = subprocess.run(args, capture_output=True, text=True, timeout=120)
        check(again.returncode == 0 and "0 to do" in again.stderr, "a second start runs nothing")
    return 0


if __name__ == "__main__":
    sys.exit(main())
