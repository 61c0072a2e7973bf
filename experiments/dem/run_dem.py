#!/usr/bin/python3
"""`make dem`: the particle (DEM) references, regenerated from the scenes with LAMMPS.

Each case of cases.toml runs once per seed of material.toml (the seeds change the grains'
diameters and their starting positions). A run generates its LAMMPS inputs from the case's
scene (lammps_input.py), runs `lmp` on them as an external program, and reduces what LAMMPS
wrote to surfaces on the reference raster and the tool's force over time (surface.py). When
every seed of a case is done, its reference file (references/CASE.h5, reference_file.py) is
written with the provenance: LAMMPS's version, the generated inputs, the seeds and the material.

Runs go to an engine (../engines.py): `local` (a pool of --jobs on this machine) or `slurm` (one
job array through sbatch, like the height-field sweeps). A finished run leaves a sidecar and
is not run again while its inputs are the same, so an interrupted `make dem` resumes.

Usage: run_dem.py [--cases NAME ...] [--seeds N ...] [--work DIR] [--out DIR] [--engine local|slurm]
       run_dem.py task MANIFEST INDEX        (a SLURM array task)
"""
import argparse
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))
import lammps_input  # noqa: E402
from case_material import material_of  # noqa: E402
import runstore  # noqa: E402
import surface  # noqa: E402

SIDECAR = "done.json"
stop_children = runstore.stop_children  # the children in flight are runstore's, whoever started them


def load_toml(path):
    with open(path, "rb") as f:
        return tomllib.load(f)


def lammps_version(lmp):
    """LAMMPS's own version line, e.g. 'LAMMPS (29 Sep 2021 - Update 2)'."""
    try:
        out = subprocess.run([lmp, "-h"], capture_output=True, text=True, timeout=60).stdout
    except (OSError, subprocess.TimeoutExpired):
        return None
    for line in out.splitlines():
        if "Large-scale Atomic/Molecular Massively Parallel Simulator" in line:
            return "LAMMPS (" + line.split(" - ", 1)[1].strip() + ")"
    return None


def lmp_command(lmp, ranks):
    """`lmp` alone, or under mpirun with RANKS ranks (Open MPI refuses root without its two
    variables; a cluster's batch jobs often run as root in containers)."""
    if ranks <= 1:
        return [lmp]
    return ["mpirun", "--oversubscribe", "-np", str(ranks), lmp]


def specs_for(cases_path, cases, seeds, work, material_path, lmp, ranks):
    """One spec per case and seed; its key changes with everything the run depends on."""
    base = load_toml(material_path)
    all_cases = load_toml(cases_path)
    version = lammps_version(lmp) or "unknown"
    generator = "".join((HERE / f).read_text() for f in ("lammps_input.py", "surface.py"))
    specs = []
    for name in cases:
        case = all_cases[name]
        scene = json.dumps(load_toml(ROOT / case["scene"]), sort_keys=True)
        material = json.dumps(material_of(case, base), sort_keys=True)  # values, not comments
        for seed in seeds:
            key = hashlib.sha256("\0".join([material, scene, json.dumps(case, sort_keys=True), version,
                                            generator, str(seed)]).encode()).hexdigest()[:16]
            specs.append({"name": f"{name}/seed{seed}", "runs": str(work), "case_name": name, "case": case,
                          "seed": seed, "material": str(material_path), "lmp": lmp, "ranks": ranks,
                          "lammps_version": version, "key": key})
    return specs


def read_sidecar(spec):
    try:
        side = json.loads((Path(spec["runs"]) / spec["name"] / SIDECAR).read_text())
    except (OSError, ValueError):
        return None
    return side if side.get("key") == spec["key"] else None


def _lammps(spec, folder, input_name, text):
    (folder / input_name).write_text(text)
    log = input_name.replace(".in", ".log")
    cmd = lmp_command(spec["lmp"], spec["ranks"]) + ["-in", input_name, "-log", log, "-screen", "none", "-nocite"]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1")
    start = time.monotonic()
    with open(folder / input_name.replace(".in", ".stderr"), "w") as err:
        proc = subprocess.Popen(cmd, cwd=folder, env=env, stdout=subprocess.DEVNULL, stderr=err)
        code, usage = runstore.wait_child(proc)
    if code != 0:
        tail = (folder / log).read_text()[-2000:] if (folder / log).exists() else ""
        raise RuntimeError(f"lmp failed ({code}) on {folder / input_name}:\n{tail}")
    return {"wall_s": round(time.monotonic() - start, 2), "cpu_s": round(usage.ru_utime + usage.ru_stime, 2)}


def execute(spec):
    """Runs one case and seed in WORK/CASE/seedN and reduces it to result.npz and the sidecar."""
    folder = Path(spec["runs"]) / spec["name"]
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    case = spec["case"]
    material = material_of(case, load_toml(spec["material"]))
    scene = load_toml(ROOT / case["scene"])
    geo = lammps_input.Geometry(scene, material)
    raster = surface.Raster(geo.origin, geo.size, material["reference"]["raster_m"])
    seed, stages, out = spec["seed"], {}, {}
    if geo.shape == "pour":
        stages["pour"] = _lammps(spec, folder, "pour.in", lammps_input.pour_input(geo, material, seed, case["pour_s"]))
        final = surface.read_dump(folder / "final.dump")
        out["initial"] = np.full((raster.ny, raster.nx), geo.bed_height)
        out["final"] = surface.envelope(final, raster, geo.floor_z)
        volumes = {"final": surface.grain_volume(final)}
        counts = {"final": len(final)}
        offset = 0.0
    else:
        stages["bed"] = _lammps(spec, folder, "bed.in", lammps_input.bed_input(geo, material, seed))
        bed = surface.read_dump(folder / "bed.dump")
        initial = surface.envelope(bed, raster, geo.floor_z)
        margin = 4 * material["grains"]["diameter_m"]
        bed_level = surface.interior_mean(initial, raster, margin)
        tool_text = lammps_input.tool_input(geo, material, case["speed_m_per_s"], bed_level)
        stages["tool"] = _lammps(spec, folder, "tool.in", tool_text)
        tool_in = surface.read_dump(folder / "tool_in.dump")
        final = surface.read_dump(folder / "final.dump")
        # Heights are stored as if the bed had settled exactly at the scene's height (the tool's
        # depth was counted from the measured level, so the cut is the scene's).
        offset = geo.bed_height - bed_level
        out["initial"] = initial + offset
        out["tool_in"] = surface.envelope(tool_in, raster, geo.floor_z) + offset
        out["final"] = surface.envelope(final, raster, geo.floor_z) + offset
        force = surface.read_force(folder / "force.txt")
        force[:, 3] += offset
        out["force"] = force
        volumes = {k: surface.grain_volume(g) for k, g in (("initial", bed), ("tool_in", tool_in), ("final", final))}
        counts = {k: len(g) for k, g in (("initial", bed), ("tool_in", tool_in), ("final", final))}
    np.savez_compressed(folder / "result.npz", **out)
    inputs = {p.name: p.read_text() for p in sorted(folder.glob("*.in"))}
    side = {"key": spec["key"], "case": spec["case_name"], "seed": seed, "stages": stages, "grains": counts,
            "grain_volume_m3": volumes, "bed_offset_m": offset, "lammps_version": spec["lammps_version"],
            "inputs": inputs, "finished": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
    (folder / SIDECAR).write_text(json.dumps(side, indent=1) + "\n")
    for dump in folder.glob("*.dump"):  # the surfaces keep what the comparison needs
        dump.unlink()
    for restart in folder.glob("*.restart"):
        restart.unlink()
    return side


def run_task(manifest, index):
    """A SLURM array task: the runs of batch INDEX of MANIFEST not yet done."""
    batch = json.loads(Path(manifest).read_text())["batches"][index]
    failed = 0
    for spec in batch:
        if read_sidecar(spec):
            continue
        try:
            execute(spec)
        except Exception as e:  # noqa: BLE001 -- one failed run must not stop the batch's others
            sys.stderr.write(f"{spec['name']}: {e}\n")
            failed += 1
    return 1 if failed else 0


def main():
    import engines
    import reference_file
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases-file", default=str(HERE / "cases.toml"), help="the cases (scenes and speeds)")
    ap.add_argument("--material", default=str(HERE / "material.toml"))
    ap.add_argument("--cases", nargs="*", help="these cases of the cases file (default: all)")
    ap.add_argument("--seeds", nargs="*", type=int, help="default: the material file's seeds")
    ap.add_argument("--work", default=str(ROOT / "build" / "dem"), help="the runs' folders")
    ap.add_argument("--out", default=str(HERE / "references"), help="the reference files")
    ap.add_argument("--lmp", default="lmp")
    ap.add_argument("--ranks", type=int, default=1, help="MPI ranks per run (mpirun); 1: lmp alone")
    ap.add_argument("--engine", choices=["local", "slurm"], default="local")
    ap.add_argument("--jobs", type=int, default=1, help="local engine: runs at once")
    ap.add_argument("--partition")
    ap.add_argument("--time")
    ap.add_argument("--poll", type=float, default=5.0)
    args = ap.parse_args()
    material_path = Path(args.material)
    try:
        all_cases = load_toml(args.cases_file)
        load_toml(material_path)
    except (OSError, tomllib.TOMLDecodeError) as e:
        sys.stderr.write(f"run_dem: {e}\n")
        return 2
    args.cases = args.cases or list(all_cases)
    unknown = [c for c in args.cases if c not in all_cases]
    if unknown:
        sys.stderr.write(f"run_dem: --cases: {', '.join(unknown)} not in {args.cases_file} "
                         f"(it has {', '.join(all_cases)})\n")
        return 2
    args.seeds = args.seeds or load_toml(material_path)["reference"]["seeds"]
    for name in args.cases:  # every case's scene checked before any run starts
        try:
            lammps_input.Geometry(load_toml(ROOT / all_cases[name]["scene"]),
                                  material_of(all_cases[name], load_toml(material_path)))
        except (OSError, KeyError, ValueError) as e:  # SceneError and TOMLDecodeError are ValueErrors
            sys.stderr.write(f"run_dem: case {name} ({all_cases[name].get('scene', 'no scene')}): {e}\n")
            return 2
    if shutil.which(args.lmp) is None:
        sys.stderr.write(f"run_dem: `{args.lmp}` not found: the references need LAMMPS (Debian: lammps); "
                         f"`make reproduce` reads the stored ones and does not\n")
        return 2
    if any(s < 1 for s in args.seeds):
        sys.stderr.write("run_dem: --seeds: positive integers\n")
        return 2
    specs = specs_for(args.cases_file, args.cases, args.seeds, Path(args.work).resolve(), material_path, args.lmp, args.ranks)
    missing = [s for s in specs if not read_sidecar(s)]
    engines.progress(f"dem: {len(specs)} runs ({len(args.cases)} cases x {len(args.seeds)} seeds), "
                     f"{len(missing)} to do on the {args.engine} engine with {specs[0]['lammps_version']}")
    if missing:
        engine = (engines.SlurmEngine(args.partition, None, args.time, None, poll_s=args.poll)
                  if args.engine == "slurm" else engines.LocalEngine(args.jobs))
        engine.execute(missing, "dem runs", runner=sys.modules[__name__])
    for name in args.cases:
        sides = [read_sidecar(s) for s in specs if s["case_name"] == name]
        folders = [Path(s["runs"]) / s["name"] for s in specs if s["case_name"] == name]
        path = reference_file.write(Path(args.out) / f"{name}.h5", name, all_cases[name],
                                    material_path, sides, folders)
        cpu = sum(st["cpu_s"] for side in sides for st in side["stages"].values())
        engines.progress(f"dem: wrote {path} ({len(sides)} seeds, {cpu:.0f} s of LAMMPS CPU)")
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "task":
        signal.signal(signal.SIGTERM, lambda *_: (stop_children(), os._exit(143)))
        sys.exit(run_task(sys.argv[2], int(sys.argv[3])))
    sys.exit(main())
