"""The engines that execute a sweep's missing runs; the experiments only declare runs and
aggregate their results, whichever engine ran them. A run is a spec of a runner module:
runstore (sandbench runs, the default) or dem/run_dem.py (particle references); a runner has
execute(spec), read_sidecar(spec), stop_children() and a `task MANIFEST INDEX` command line.

- LocalEngine: a pool of `jobs` threads on this machine, each running one sandbench at a time.
- SlurmEngine: one SLURM job array through `sbatch`, one array task per batch of runs,
  at most `parallel` tasks at once (`--array=0-K%N`); polls `squeue` until the array has
  left the queue, then the driver checks that every run left its sidecar.

Both execute the same runner.execute() on the same specs, so their run files and sidecars
are the same apart from timings. A stopped sweep (Ctrl-C, SIGTERM) stops its runs (the local
children, or `scancel` of the array); the finished ones keep their sidecars and the next
start runs only the rest. If the driver dies without cleaning up (kill -9), the job array it
submitted is recorded in RUNS/.slurm/pending.json and the next start waits for it first.
"""
import concurrent.futures
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import runstore

HERE = Path(__file__).resolve().parent


def progress(message):
    sys.stderr.write(message + "\n")
    sys.stderr.flush()


class _StopOnSignals:
    """SIGINT/SIGTERM call on_stop() then exit 128+signal (the default would leave children
    running, or wait for a thread pool to drain)."""

    def __init__(self, on_stop):
        self.on_stop = on_stop
        self.saved = {}

    def __enter__(self):
        for s in (signal.SIGINT, signal.SIGTERM):
            self.saved[s] = signal.signal(s, self._handle)
        return self

    def _handle(self, signum, _frame):
        progress(f"stopping on signal {signum}: finished runs are kept, the next start runs the rest")
        self.on_stop()
        os._exit(128 + signum)

    def __exit__(self, *exc):
        for s, h in self.saved.items():
            signal.signal(s, h)


class LocalEngine:
    name = "local"

    def __init__(self, jobs=2):
        self.jobs = jobs

    def execute(self, specs, label="runs", runner=runstore):
        done = [0]
        lock = threading.Lock()

        def one(spec):
            runner.execute(spec)
            with lock:
                done[0] += 1
                progress(f"  {label}: {done[0]}/{len(specs)} {spec['name']}")

        with _StopOnSignals(runner.stop_children):
            with concurrent.futures.ThreadPoolExecutor(max_workers=self.jobs) as pool:
                for f in [pool.submit(one, s) for s in specs]:
                    f.result()


class SlurmEngine:
    """Options (None: the cluster's default): partition, account, time (sbatch --time, per
    array task), mem (sbatch --mem), parallel (the %N throttle), batch (runs per array task),
    extra (more sbatch arguments), poll_s (seconds between squeue polls)."""
    name = "slurm"
    MAX_ARRAY_TASKS = 1000  # SLURM's default MaxArraySize is 1001; larger sweeps get bigger batches

    def __init__(self, partition=None, account=None, time=None, mem=None, parallel=32, batch=1, extra=(),
                 poll_s=5.0):
        self.partition, self.account, self.time, self.mem = partition, account, time, mem
        self.parallel, self.batch, self.extra, self.poll_s = parallel, batch, list(extra), poll_s
        self.job_ids = []  # every array this engine waited for, in order
        for tool in ("sbatch", "squeue", "scancel"):
            if not shutil.which(tool):
                raise RuntimeError(f"the slurm engine needs `{tool}` on PATH (Debian: slurm-client), and a "
                                   f"cluster that can read this folder")

    def execute(self, specs, label="runs", runner=runstore):
        state = Path(specs[0]["runs"]) / ".slurm"
        state.mkdir(parents=True, exist_ok=True)
        pending = state / "pending.json"
        if pending.exists():  # a driver killed without cleaning up: its array may still be running
            old = json.loads(pending.read_text())["job"]
            if self._active(old) != []:
                progress(f"slurm: job array {old} of an earlier start is still queued; waiting for it first")
                self._wait(old)
            pending.unlink()
            specs = [s for s in specs if not runner.read_sidecar(s)]
            if not specs:
                return
        batch = max(self.batch, math.ceil(len(specs) / self.MAX_ARRAY_TASKS))
        batches = [specs[i:i + batch] for i in range(0, len(specs), batch)]
        stamp = time.strftime("%Y%m%d-%H%M%S", time.gmtime())
        manifest = state / f"sweep-{stamp}-{os.getpid()}.json"
        manifest.write_text(json.dumps({"batches": batches}) + "\n")
        cmd = ["sbatch", "--parsable", f"--array=0-{len(batches) - 1}%{self.parallel}", "--job-name=sandbench",
               f"--output={state}/%A_%a.log", f"--chdir={specs[0]['runs']}", "--cpus-per-task=1"]
        for flag, value in (("partition", self.partition), ("account", self.account), ("time", self.time),
                            ("mem", self.mem)):
            if value:
                cmd.append(f"--{flag}={value}")
        cmd += self.extra + [f"--wrap=exec /usr/bin/python3 {Path(runner.__file__).resolve()} task {manifest} "
                             f"$SLURM_ARRAY_TASK_ID"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"sbatch refused the sweep ({proc.returncode}): {' '.join(cmd)}\n{proc.stderr}")
        job = proc.stdout.strip().split(";")[0]
        pending.write_text(json.dumps({"job": job, "manifest": str(manifest)}) + "\n")
        progress(f"slurm: submitted job array {job}: {len(specs)} {label} in {len(batches)} tasks of up to "
                 f"{batch}, at most {self.parallel} at once; logs in {state}/{job}_<task>.log")
        with _StopOnSignals(lambda: self._cancel(job)):
            self._wait(job, len(batches))
        pending.unlink()
        self.job_ids.append(job)
        failed = [(i, s) for i, b in enumerate(batches) for s in b if not runner.read_sidecar(s)]
        for i, s in failed[:5]:
            log = state / f"{job}_{i}.log"
            tail = log.read_text()[-1500:] if log.exists() else "(no log)"
            progress(f"slurm: {s['name']} did not finish (task {i}, {log}):\n{tail}")
        if failed:
            raise RuntimeError(f"slurm: {len(failed)} of {len(specs)} runs of job array {job} did not finish")
        progress(f"slurm: job array {job} finished ({len(batches)} tasks)")

    def _active(self, job):
        """States of the array's tasks still in the queue (empty when the array has left it);
        None when squeue could not answer (the controller busy or restarting: ask again)."""
        proc = subprocess.run(["squeue", "--noheader", "--array", f"--jobs={job}", "--format=%T"],
                              capture_output=True, text=True)
        if proc.returncode != 0:
            if "Invalid job id" in proc.stderr:  # long finished and purged from the controller
                return []
            progress(f"slurm: squeue failed, asking again: {proc.stderr.strip()}")
            return None
        return proc.stdout.split()

    def _wait(self, job, tasks=None):
        last = None
        while True:
            states = self._active(job)
            if states is None:
                time.sleep(max(self.poll_s, 5.0))
                continue
            if not states:
                return
            running = states.count("RUNNING")
            if (len(states), running) != last:
                total = f" of {tasks}" if tasks else ""
                progress(f"slurm: job {job}: {len(states)}{total} tasks queued or running ({running} running)")
                last = (len(states), running)
            time.sleep(self.poll_s)

    def _cancel(self, job):
        subprocess.run(["scancel", job], capture_output=True)
        progress(f"slurm: cancelled job array {job}")
