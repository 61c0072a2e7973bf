#!/usr/bin/python3
"""The slurm engine against a real SLURM cluster (CTest label `slurm`).

Starts a single-node cluster on localhost (local_cluster.py), then:
1. runs the tiny reproduction profile on the local engine into one folder;
2. runs it on the slurm engine into another, stops the driver (SIGTERM) once part of the
   runs are done -- its job array is cancelled -- and starts it again: the second start must
   submit exactly the runs that were missing and reuse the others untouched;
3. checks that both engines' tables are identical apart from timing columns, and that their
   run files hold the same final surfaces;
4. runs the tiny particle reference case (tests/dem/) through the same engine as a job array
   (when LAMMPS's `lmp` is installed) and checks that it writes the same surfaces as a local run;
5. prints the job ids it waited for; stops every daemon it started, also on failure.

Usage: slurm_sweep_test.py SANDBENCH
"""
import re
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "tests" / "sweeps"))
import local_cluster  # noqa: E402
from sweep_checks import compare_tables, compare_run_files, sidecars  # noqa: E402

REPRODUCE = [sys.executable, str(ROOT / "experiments" / "reproduce.py"), "--profile", "tiny"]
BATCH = 3  # runs per array task: fewer, longer tasks (each costs the scheduler a second or two)


def log(message):
    print(message, flush=True)


def slurm_sweep(cluster, sandbench, results, stop_after=None):
    """The tiny profile on the slurm engine; with stop_after, SIGTERM the driver once that many
    runs have finished. Returns (exit code, stderr)."""
    cmd = REPRODUCE + ["--sandbench", sandbench, "--results", str(results), "--engine", "slurm", "--poll", "0.5",
                       "--parallel", "4", "--batch", str(BATCH)]
    err_path = results.parent / f"{results.name}-driver-{time.monotonic_ns()}.log"
    with open(err_path, "w") as err:
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err, env=cluster.env)
        if stop_after is not None:
            while proc.poll() is None and len(sidecars(results)) < stop_after:
                time.sleep(0.2)
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)
        code = proc.wait(timeout=900)
    return code, err_path.read_text()


def job_ids(stderr):
    return re.findall(r"slurm: submitted job array (\d+)", stderr)


RUN_DEM = [sys.executable, str(ROOT / "experiments" / "dem" / "run_dem.py"), "--cases-file",
           str(ROOT / "tests" / "dem" / "tiny_cases.toml"), "--seeds", "1"]


def dem_sweep(cluster, tmp):
    """The tiny particle case on the local engine and as a job array; failures as strings."""
    import shutil
    if shutil.which("lmp") is None:
        log("dem: lmp not found, the particle case through slurm skipped")
        return []
    sys.path.insert(0, str(ROOT / "experiments" / "dem"))
    import numpy as np
    import reference_file
    out = {}
    for engine in ("local", "slurm"):
        cmd = RUN_DEM + ["--work", str(tmp / f"dem-{engine}"), "--out", str(tmp / f"dem-{engine}-ref"),
                         "--engine", engine, "--poll", "0.5"]
        proc = subprocess.run(cmd, capture_output=True, text=True, env=cluster.env, timeout=600)
        if proc.returncode != 0:
            return [f"run_dem.py on the {engine} engine failed ({proc.returncode}):\n{proc.stderr[-3000:]}"]
        if engine == "slurm" and not job_ids(proc.stderr):
            return ["run_dem.py on the slurm engine submitted no job array"]
        log(f"dem: the tiny case on the {engine} engine {'(job array ' + job_ids(proc.stderr)[0] + ')' if engine == 'slurm' else ''}")
        out[engine] = reference_file.Reference(tmp / f"dem-{engine}-ref" / "tiny.h5")
    if not all(np.array_equal(out["local"].surfaces[k], out["slurm"].surfaces[k]) for k in out["local"].surfaces):
        return ["the particle case's surfaces differ between the local and the slurm engine"]
    return []


def main():
    sandbench = str(Path(sys.argv[1]).resolve())
    failures = []
    start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="sbsweep-") as tmp:
        tmp = Path(tmp)
        local = tmp / "local"
        proc = subprocess.run(REPRODUCE + ["--sandbench", sandbench, "--results", str(local), "--engine", "local"],
                              capture_output=True, text=True)
        if proc.returncode != 0:
            sys.exit(f"the local engine failed ({proc.returncode}):\n{proc.stderr[-4000:]}")
        total = len(sidecars(local))
        log(f"local engine: {total} runs in {time.monotonic() - start:.0f} s")

        with local_cluster.LocalCluster(log) as cluster:
            try:
                slurm = tmp / "slurm"
                code, err1 = slurm_sweep(cluster, sandbench, slurm, stop_after=max(1, total // 3))
                before = sidecars(slurm)
                log(f"slurm engine, first start: stopped (exit {code}) with {len(before)} of {total} runs done; "
                    f"job arrays {job_ids(err1)}")
                if code == 0:
                    failures.append("the first start was not stopped before it ended: nothing tested about resuming")
                time.sleep(1)  # the cancelled tasks' last sidecar writes
                before = sidecars(slurm)
                code, err2 = slurm_sweep(cluster, sandbench, slurm)
                if code != 0:
                    raise RuntimeError(f"the second start failed ({code}):\n{err2[-4000:]}")
                todo = re.findall(r"round 1: (\d+) runs to do", err2)
                expected = total - len(before)
                if [int(t) for t in todo] != [expected]:
                    failures.append(f"the second start did {todo} runs in its first round, {expected} were missing")
                after = sidecars(slurm)
                changed = [n for n, stamp in before.items() if after.get(n) != stamp]
                if changed:
                    failures.append(f"the second start ran again {len(changed)} finished runs: {changed[:5]}")
                waited = job_ids(err1) + job_ids(err2)
                log(f"slurm engine, second start: {todo} runs in job arrays {job_ids(err2)}")
                log(f"job ids waited for: {' '.join(waited)}")
                if not job_ids(err2) and expected:
                    failures.append("no job array was submitted")
                failures += dem_sweep(cluster, tmp)
                for job in waited:  # the cluster's own record of them (kept MinJobAge seconds)
                    info = cluster.run(["scontrol", "show", "job", job], check=False).stdout
                    states = sorted(set(re.findall(r"JobState=(\w+)", info)))
                    log(f"  job {job}: {len(re.findall(r'(?<!Array)JobId=', info))} array tasks, states {states}")
            except BaseException:
                log(cluster.logs())
                raise
            finally:
                daemons = dict(cluster.procs)
            trouble = cluster.stop()
        if trouble:
            failures.append(f"daemons that would not stop on SIGTERM: {trouble}")
        alive = [f"{n} (pid {p.pid})" for n, p in daemons.items() if p.poll() is None]
        if alive:
            failures.append(f"daemons still running: {alive}")
        failures += compare_tables(local, slurm)
        failures += compare_run_files(local / "runs", slurm / "runs")
        log(f"tables and run files compared; total {time.monotonic() - start:.0f} s")
    if failures:
        print("\n".join(f"FAIL: {f}" for f in failures))
        sys.exit(1)
    print("1 passed, 0 failed")


if __name__ == "__main__":
    main()
