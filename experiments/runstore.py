#!/usr/bin/python3
"""One declared sandbench run: what identifies it, where its files go, how it is executed,
and whether a finished one may be reused. Standard library only: SLURM array tasks import
this file on compute nodes (`runstore.py task MANIFEST INDEX`).

A run is a scene, a back-end, --set overrides and an output name. Its *key* hashes what
decides its result: the binary's build identity (`sandbench --version`: "build <16 hex>",
a hash of the binary's sources and compiler configuration), the scene file's bytes, the
bytes of files the scene names (keys ending in "path", e.g. terrain.path), the back-end, the
overrides and the time limit. The name is only where the files go.

Files of run NAME, in the runs folder:
  NAME.h5    the run file (sandbench writes it under a temporary name and renames it whole)
  NAME.json  the sidecar, written atomically after the run ends: key, identity, binary
             (commit and build), exit code, the end of stderr, the summary, wall and CPU time.
A run is reused only when its sidecar holds the same key (and, for a run that succeeded,
its run file exists); anything else -- no sidecar, a sidecar from another binary or other
inputs, an older sidecar format -- runs again. Killing a sweep therefore loses at most the
runs in flight.
"""
import hashlib
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

SIDECAR_FORMAT = 2
STDERR_KEPT = 2000  # characters of stderr kept in the sidecar (the reason of a refusal)


def sha256_file(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def binary_identity(sandbench):
    """{"version", "commit", "build_id"} of a sandbench binary, from its --version line.
    A binary without a build stamp is identified by the hash of its bytes."""
    proc = subprocess.run([str(sandbench), "--version"], capture_output=True, text=True)
    line = proc.stdout.strip()
    m = re.search(r"commit (\S+) build ([0-9a-f]+)", line)
    if proc.returncode == 0 and m:
        return {"version": line, "commit": m.group(1), "build_id": m.group(2)}
    if not Path(sandbench).is_file():
        raise RuntimeError(f"sandbench binary not found: {sandbench} (run `make build`)")
    return {"version": line or "unknown", "commit": "unknown", "build_id": "file-" + sha256_file(sandbench)[:16]}


def referenced_files(scene, overrides):
    """Files the scene names (string values of keys ending in "path", relative to the scene's
    folder), so that editing a heightmap invalidates the runs that read it."""
    names = []
    try:
        import tomllib
        with open(scene, "rb") as f:
            doc = tomllib.load(f)

        def walk(table):
            for k, v in table.items():
                if isinstance(v, dict):
                    walk(v)
                elif k.endswith("path") and isinstance(v, str):
                    names.append(v)
        walk(doc)
    except Exception:  # not TOML (a deliberately broken scene) or no tomllib: nothing referenced
        pass
    for o in overrides:
        key, _, value = o.partition("=")
        if key.strip().endswith("path"):
            names.append(value.strip().strip("'\""))
    files = {}
    for n in names:
        p = Path(n) if os.path.isabs(n) else Path(scene).parent / n
        if p.is_file():
            files[n] = sha256_file(p)
    return files


def make_spec(sandbench, binary, runs_dir, scene, backend, name, overrides=(), check=True, timeout=None):
    """The JSON-able description of one run, with its key."""
    scene = Path(scene).resolve()
    overrides = [str(o) for o in overrides]
    identity = {"build_id": binary["build_id"], "backend": backend, "overrides": overrides,
                "scene_sha256": sha256_file(scene), "inputs": referenced_files(scene, overrides)}
    if timeout is not None:
        identity["timeout_s"] = timeout
    key = hashlib.sha256(json.dumps(identity, sort_keys=True).encode()).hexdigest()[:20]
    runs_dir = Path(runs_dir).resolve()
    # Paths under the runs folder are given relative to it (the working directory of the run),
    # so run files and messages do not depend on where the results folder is.
    scene_arg = os.path.relpath(scene, runs_dir) if runs_dir in scene.parents else str(scene)
    return {"name": name, "backend": backend, "scene": scene_arg, "overrides": overrides, "check": check,
            "timeout": timeout, "sandbench": str(Path(sandbench).resolve()), "runs": str(runs_dir), "key": key,
            "identity": identity, "binary": {"commit": binary["commit"], "build_id": binary["build_id"]}}


def run_file(spec):
    return Path(spec["runs"]) / f"{spec['name']}.h5"


def sidecar_path(spec):
    return Path(spec["runs"]) / f"{spec['name']}.json"


def read_sidecar(spec):
    """The sidecar if it belongs to this very run (same key, run file present if it succeeded)."""
    try:
        side = json.loads(sidecar_path(spec).read_text())
    except (OSError, ValueError):
        return None
    if side.get("format") != SIDECAR_FORMAT or side.get("key") != spec["key"]:
        return None
    if side.get("exit") == 0 and not run_file(spec).exists():
        return None
    return side


def command(spec):
    cmd = [spec["sandbench"], "run", spec["scene"], "--backend", spec["backend"], "--out", f"{spec['name']}.h5",
           "--json"]
    for o in spec["overrides"]:
        cmd += ["--set", o]
    return cmd


class RunFailed(RuntimeError):
    pass


# Children in flight, so that a driver told to stop can stop them too (see stop_children).
_children = set()
_children_lock = threading.Lock()
_checked_binaries = {}


def _check_binary(spec):
    """The binary at spec's path must still be the one the run was planned with (a rebuild in
    the middle of a sweep would otherwise file new results under the old identity)."""
    path = spec["sandbench"]
    if path not in _checked_binaries:
        _checked_binaries[path] = binary_identity(path)["build_id"]
    if _checked_binaries[path] != spec["binary"]["build_id"]:
        raise RunFailed(f"{path} is build {_checked_binaries[path]}, the sweep was planned with build "
                        f"{spec['binary']['build_id']}: it was rebuilt during the sweep; start the sweep again")


def execute(spec):
    """Runs one spec and writes its sidecar; returns the sidecar. A failing run with check
    set raises RunFailed and writes no sidecar (it runs again next time); without check the
    exit code and stderr are the result (the stability matrix classifies them)."""
    _check_binary(spec)
    cmd = command(spec)
    Path(spec["runs"], spec["name"]).parent.mkdir(parents=True, exist_ok=True)
    start = time.monotonic()
    # Output to files and our own wait4, to learn the run's CPU time (what a cluster bills).
    with tempfile.TemporaryFile("w+") as fout, tempfile.TemporaryFile("w+") as ferr:
        proc = subprocess.Popen(cmd, cwd=spec["runs"], stdout=fout, stderr=ferr, text=True)
        with _children_lock:
            _children.add(proc)
        timed_out = threading.Event()

        def kill():
            timed_out.set()
            proc.kill()
        timer = threading.Timer(spec["timeout"], kill) if spec["timeout"] else None
        if timer:
            timer.start()
        try:
            _, status, usage = os.wait4(proc.pid, 0)
        finally:
            if timer:
                timer.cancel()
            with _children_lock:
                _children.discard(proc)
        proc.returncode = os.waitstatus_to_exitcode(status)
        code = None if timed_out.is_set() else proc.returncode
        fout.seek(0)
        ferr.seek(0)
        out, err = fout.read(), ferr.read()
    if code != 0 and spec["check"]:
        raise RunFailed(f"sandbench failed ({code}): {' '.join(cmd)} (in {spec['runs']})\n{err[-STDERR_KEPT:]}")
    summary = {}
    if code == 0:
        summary = json.loads(out)
    side = {"format": SIDECAR_FORMAT, "key": spec["key"], "name": spec["name"], "identity": spec["identity"],
            "binary": spec["binary"], "exit": code, "stderr": err[-STDERR_KEPT:], "summary": summary,
            "wall_s": round(time.monotonic() - start, 3), "cpu_s": round(usage.ru_utime + usage.ru_stime, 3),
            "finished": time.strftime("%Y-%m-%d", time.gmtime())}
    path = sidecar_path(spec)
    tmp = path.with_name(f"{path.name}.tmp{os.getpid()}.{threading.get_ident()}")
    tmp.write_text(json.dumps(side, indent=1) + "\n")
    tmp.replace(path)
    return side


def wait_child(proc):
    """Waits for PROC, a child that stop_children() may kill meanwhile; (exit code, resource usage)."""
    with _children_lock:
        _children.add(proc)
    try:
        _, status, usage = os.wait4(proc.pid, 0)
    finally:
        with _children_lock:
            _children.discard(proc)
    return os.waitstatus_to_exitcode(status), usage


def stop_children():
    """Kills every run in flight (the driver is being stopped)."""
    with _children_lock:
        for p in list(_children):
            try:
                p.kill()
            except OSError:
                pass


def run_task(manifest, index):
    """A SLURM array task: the runs of batch INDEX of MANIFEST, skipping those already done.
    Exit 1 when one of them failed (the others still run)."""
    m = json.loads(Path(manifest).read_text())
    batch = m["batches"][index]
    failed = 0
    for spec in batch:
        if read_sidecar(spec):
            print(f"{spec['name']}: already done", flush=True)
            continue
        try:
            side = execute(spec)
            print(f"{spec['name']}: exit {side['exit']} in {side['wall_s']} s", flush=True)
        except Exception as e:  # report and go on with the batch
            failed += 1
            print(f"{spec['name']}: FAILED: {e}", file=sys.stderr, flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "task":
        signal.signal(signal.SIGTERM, lambda *_: (stop_children(), os._exit(143)))
        sys.exit(run_task(sys.argv[2], int(sys.argv[3])))
    sys.exit("usage: runstore.py task MANIFEST INDEX (run by the slurm engine's array tasks)")
